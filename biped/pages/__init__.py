"""What a reader looks at: the paper's figures and comparison table from a sweep
(``figures``), a Markdown page per gait file (``page``), and the figures of a walk's orbit
and of MuJoCo's walk beside the model's drawn from a validation report's JSON
(``orbit_figures``, ``walk_figures``), the figures of a designed knee profile and of it over
the speeds (``profile_figures``), a two-phase gait's page and figures (``two_phase_page``,
``two_phase_figures``), the design map's figures (``design_map_figures``), a
robustness map's (``robustness_figure``), the optima over nested gait families
(``converge_figures``), every criterion on each criterion's optimum (``criteria_page``,
``criteria_figures``), two atlases in two gait families cell by cell (``atlas_families``),
a sweep with double support (``two_phase_sweep_figures``), an atlas with double support
(``atlas_two_phase``); every figure of the project drawn in one style and written by one
function (``style``).

May import: every other layer of ``biped``, numpy, matplotlib.
"""

"""Campaigns of many optimizations written as files and resumable: the sweep over speed
(``sweep``), the map of knee radii (``design_map``), the paper's own method over seeds
(``paper_method``), each its science on the one mechanism that claims a folder, resumes, runs
stages on a pool or Dask, shows progress and summarizes (``campaign``), their stages and the
neighbours that start a point declared and ordered once (``staging``); and a machined knee
profile over the speeds (``profile_speeds``: a table of optimizations, no folder of its own),
both knees over nested gait families until their comparison converges (``converge``),
each criterion's optimum with every criterion measured on it (``criteria_matrix``), and two
atlases in two gait families compared cell by cell (``atlas_families``); a sweep's
two-phase optima beside its single-support ones (``two_phase_sweep``), and an atlas's
(``atlas_two_phase``).

May import: ``biped.model``, ``biped.optimization``, ``biped.records``, ``biped.runtime``,
``biped.errors``, numpy (the design map's figures are ``biped.pages.design_map_figures``).
"""

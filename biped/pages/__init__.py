"""What a reader looks at: the paper's figures and comparison table from a sweep
(``figures``) and a Markdown page per gait file (``page``).

May import: every other layer of ``biped``, matplotlib.
"""

"""What a validation leaves to look at: its Rerun recording (``record``), its video
(``video``), and where a gait's outputs go and which gait a recording belongs to
(``outputs``).

May import: ``validate.checks``, ``validate.walk``, ``validate.scene``, every layer of
``biped``, ``validate`` (its ``__init__``), numpy, mujoco, rerun, imageio-ffmpeg, Pillow and
matplotlib (its fonts).
"""

"""Physics validation of analytical gaits in MuJoCo (models, cross-checks, recordings)."""

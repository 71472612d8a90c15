"""The thesis's experiments reproduced on the simulated Jackal in one command
(scripts/aic_reproduce.py): the whole run and its plots (reproduce), the runs and their verdicts
(reproduce_runs) and the tables in the thesis's layout (reproduce_tables)."""

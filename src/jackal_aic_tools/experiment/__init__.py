"""Step-response experiments on the simulated Jackal under their own ROS master: one run
(experiment; scripts/aic_experiment.py) and sweeps of runs across parameters (sweep;
scripts/aic_sweep.py)."""

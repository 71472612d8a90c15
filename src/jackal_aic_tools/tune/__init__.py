"""Tuning the controller and the criteria it is judged by: the model-based and the driving
tuning (tune, tune_space, tune_cost, tune_driving; scripts/aic_tune.py) and the tuning acceptance
set with its printout (scorecard, scorecard_print; scripts/aic_scorecard.py)."""

"""Field trials on the robot (doc/field_trials.md): the session plans (field_plan), the safety
rules (field_safety), the trial node (field_trial; scripts/aic_field_trial.py) and the report of a
session (field_report; scripts/aic_field_report.py)."""

"""Experiment tooling for jackal_aic: set-point profiles, recording, stability
monitoring, step metrics (through the core's ``aic_step_metrics`` CLI), tables and plots.

Used by ``scripts/aic_experiment.py``, ``scripts/aic_sweep.py`` and the step-response
rostests. Metric definitions follow thesis ch. 5 (doc/active_inference.md, 'Step-response
metrics and experiments').
"""

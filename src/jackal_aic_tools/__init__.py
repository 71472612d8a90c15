"""The Python tools of jackal_aic (the entry points are scripts/*.py), in named subpackages:

  common      what every tool shares: command-line helpers, set-point profiles, recording and
              the stability monitor, step and tracking metrics (through the core's CLIs),
              tables, reports and plots, and the launcher and stop routine of ROS processes
  compare     named controller variants side by side against the stock controller and the
              latency floor, and run_variant, the Python API of one headless run (aic_compare.py)
  experiment  step-response experiments on the simulated Jackal and sweeps of them
              (aic_experiment.py, aic_sweep.py)
  reproduce   the thesis's tables reproduced on the simulated Jackal (aic_reproduce.py)
  track       the tracking benchmark and the driving acceptance set on the headless closed loop
              (aic_track.py; the ideal controller, the plant-limited pairs)
  tune        tuning the controller and the acceptance criteria it is judged by (aic_tune.py,
              aic_scorecard.py)
  identify    identification of the Jackal's wheel loop (plant_identify.py,
              record_identification.py)
  field       field trials on the robot: plans, safety rules, the trial node and the report
              (aic_field_trial.py, aic_field_report.py)
  robustness  the ROS soak, the ROS fuzz and the node's CPU cost, through the real nodes
              (aic_ros_soak.py, aic_ros_fuzz.py, aic_node_load.py)

Metric definitions follow thesis ch. 5 (doc/active_inference.md, 'Step-response metrics and
experiments').
"""

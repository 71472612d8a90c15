"""The tracking benchmark of real driving and the driving acceptance set, headless on the
simulated Jackal's plant core (closed_loop_run): the profiles (track_profiles), the runs
(track_suite; scripts/aic_track.py) and their report (track_report), the driving acceptance set
(driving), the plant-limited pairs against the ideal controller (plant_limits) and the ideal
controller's runs kept between benchmark runs (ideal_cache)."""

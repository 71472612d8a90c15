"""What the tools share: command-line helpers (cli), set-point profiles (profiles), recording
and the stability monitor (recording), step and tracking metrics through the core's CLIs (metrics,
tracking), the formatter of figures and tables (tables), the style and the files of every plot
(figures), the reports, plots and result summaries (report, summary) and the launcher and stop
routine of ROS processes (ros_process)."""

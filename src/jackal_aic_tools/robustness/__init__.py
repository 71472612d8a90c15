"""The jackal_AIC node through ROS, its real nodes on the wall clock: the ROS soak (soak;
scripts/aic_ros_soak.py), the ROS fuzz (ros_fuzz; scripts/aic_ros_fuzz.py) and the node's CPU cost
and latency (node_load; scripts/aic_node_load.py), with what they watch of the running nodes
(node_watch: the command check, the diagnostics counters, resource use through psutil)."""

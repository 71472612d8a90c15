#!/usr/bin/env python3
"""rostest: each invalid parameter makes jackal_aic_node exit non-zero and name the
parameter in its log; a valid set keeps it running (so the check can fail).

Runs the node binary once per case (WORKERS at a time) against the rostest master, under a unique node
name whose private namespace holds the valid config/default.yaml plus the case's override
(set on the parameter server, as a launch file's rosparam would).

Parameters (~): exit_timeout [s] (how long an invalid node may take to exit),
alive_time [s] (how long the valid node must stay up).
"""
import concurrent.futures
import os
import subprocess
import sys
import unittest

import rospkg
import rospy
import rostest
import yaml

from jackal_aic_tools.common import ros_process

# (case, overrides {key: value, or None to leave the key out}, parameter the log must name)
CASES = [
    ("tau_negative", {"tau": -1.0}, "tau"),
    ("tau_zero", {"tau": 0.0}, "tau"),
    ("var_mu_zero", {"var_mu": [1.5, 0.0, 4.0, 8.0]}, "var_mu[1]"),
    ("var_y_negative", {"var_y": [2.0, -2.0, 100000.0, 100000.0]}, "var_y[1]"),
    ("var_mu_wrong_size", {"var_mu": [1.5, 2.0]}, "var_mu"),
    ("order_zero", {"embedding_order": 0}, "embedding_order"),
    ("order_six", {"embedding_order": 6}, "embedding_order"),
    ("belief_below_action", {"belief_rate": 20.0, "action_rate": 50.0}, "belief_rate"),
    ("left_joints_missing", {"left_joints": None}, "left_joints"),
    ("right_joints_empty", {"right_joints": []}, "right_joints"),
    ("left_joint_name_empty", {"left_joints": ["front_left_wheel", ""]}, "left_joints[1]"),
    ("tau_not_a_number", {"tau": "fast"}, "tau"),
    ("integrator_unknown", {"integrator": "rk4"}, "integrator"),
    ("order_not_an_integer", {"embedding_order": 2.5}, "embedding_order"),
    # node-only rules (NodeParams::validate)
    ("belief_rate_beyond_max_loop_rate", {"belief_rate": 20000.0}, "belief_rate"),
    ("sensor_timeout_zero", {"sensor_timeout": 0.0}, "sensor_timeout"),
    ("set_point_timeout_negative", {"set_point_timeout": -0.5}, "set_point_timeout"),
    ("imu_max_skew_zero", {"imu_max_skew": 0.0}, "imu_max_skew"),
    ("min_sample_interval_beyond_sensor_timeout", {"min_sample_interval": 0.3}, "min_sample_interval"),
    ("max_linear_speed_zero", {"max_linear_speed": 0.0}, "max_linear_speed"),
    ("max_angular_speed_negative", {"max_angular_speed": -4.0}, "max_angular_speed"),
    ("runaway_hold_time_negative", {"runaway_hold_time": -1.0}, "runaway_hold_time"),
    ("left_joint_listed_twice", {"left_joints": ["front_left_wheel", "front_left_wheel"]}, "left_joints[1]"),
    ("joint_on_both_sides", {"right_joints": ["front_right_wheel", "front_left_wheel"]}, "right_joints"),
    ("output_mode_unknown", {"output_mode": "cmd_pwm"}, "output_mode"),
    ("cmd_vel_wheel_radius_zero", {"cmd_vel_wheel_radius": 0.0}, "cmd_vel_wheel_radius"),
    ("cmd_vel_max_linear_acceleration_nan", {"cmd_vel_max_linear_acceleration": float("nan")},
     "cmd_vel_max_linear_acceleration"),
]

WORKERS = 4  # nodes started at a time: each only reads its parameters and exits


class InvalidParamsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        pkg = rospkg.RosPack().get_path("jackal_aic")
        with open(os.path.join(pkg, "config", "default.yaml")) as f:
            cls.valid = yaml.safe_load(f)
        import roslib.packages
        found = roslib.packages.find_node("jackal_aic", "jackal_aic_node")
        assert found, "jackal_aic_node not built"
        cls.binary = found[0]
        cls.exit_timeout = float(rospy.get_param("~exit_timeout", 20.0))
        cls.alive_time = float(rospy.get_param("~alive_time", 2.0))

    def args(self, name, overrides):
        """Put default.yaml with the overrides (None: key removed) into /<name>/ on the master; return
        the command line."""
        if rospy.has_param("/" + name):
            rospy.delete_param("/" + name)
        params = dict(self.valid)
        params.update(overrides)  # default.yaml holds the joints only: most overrides add a key
        for key, value in params.items():
            if value is None:  # the case removes the key
                continue
            rospy.set_param("/%s/%s" % (name, key), value)
        return [self.binary, "__name:=" + name]

    def test_valid_parameters_keep_running(self):
        # integers where the node reads doubles (as a hand-written YAML may have them) are valid
        # (var_y: one per order of default.yaml's embedding order, 2)
        valid = {"belief_rate": 1000, "action_rate": 50, "k_a": 8, "var_y": [2, 20, 100000]}
        proc = ros_process.start(self.args("aic_valid", valid), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                 text=True)
        try:
            out, err = proc.communicate(timeout=self.alive_time)
            self.fail("the node exited (%s) with valid parameters:\n%s\n%s" % (proc.returncode, out, err))
        except subprocess.TimeoutExpired:
            ros_process.stop(proc, timeout=10.0)
            proc.communicate()

    def test_each_invalid_parameter_exits_non_zero(self):
        # Each case's node is independent (its own name and parameters): up to WORKERS at a time.
        commands = [(case, self.args("aic_" + case, overrides), name) for case, overrides, name in CASES]

        def run(item):
            case, command, name = item
            proc = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                  timeout=self.exit_timeout)
            return case, name, proc.returncode, proc.stdout + proc.stderr

        with concurrent.futures.ThreadPoolExecutor(max_workers=WORKERS) as pool:
            results = list(pool.map(run, commands))
        self.assertEqual(len(results), len(CASES))
        for case, name, returncode, log in results:
            with self.subTest(case=case):
                self.assertNotEqual(returncode, 0, "%s: exit code 0\n%s" % (case, log))
                self.assertIn("invalid parameter ~" + name, log, "%s: the log does not name %s\n%s"
                              % (case, name, log))
                print("OK %s: exit %d, '%s'" % (case, returncode,
                                                [l for l in log.splitlines() if "~" + name in l][0].strip()),
                      file=sys.stderr)

if __name__ == "__main__":
    rospy.init_node("test_invalid_params")
    rostest.rosrun("jackal_aic", "test_invalid_params", InvalidParamsTest, sys.argv)

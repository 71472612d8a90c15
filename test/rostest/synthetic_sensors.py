#!/usr/bin/env python3
"""Shared rostest fixture: a synthetic Jackal for the jackal_AIC node tests.

Publishes /joint_states and /imu/data (not hardware-synchronized: the IMU is stamped and
sent `imu_offset` after the joint states) at `rate`, and a set point on
/jackal_AIC/set_point at `set_point_rate`. The sensors report a constant motion
(open loop: they do not react to /cmd_drive), which is what the direction tests need.

Private parameters (all optional):
  rate [Hz] 50.0                 sensor rate
  imu_offset [s] 0.007           IMU stamp/publication offset after the joint states
  wheel_speed [rad/s] 0.0        reported velocity of every wheel joint (both sides)
  gyro_z [rad/s] 0.0             reported yaw rate
  accel_x, accel_y [m/s^2] 0.0   reported accelerations (accel z is 9.81)
  set_point_linear [m/s] 0.5     set point linear.x
  set_point_angular [rad/s] 0.0  set point angular.z
  set_point_rate [Hz] 20.0       set point rate
  start_delay [s] 0.5            wait before publishing anything
  sensors_stop_at [s] -1         stop the sensors this long after the start (-1: never)
  sensors_resume_at [s] -1       resume them (-1: never)
  set_point_stop_at [s] -1       stop the set point (-1: never)
  set_point_resume_at [s] -1     resume it (-1: never)
  faults [bool] false            interleave invalid messages (every numeric field NaN/+Inf/-Inf
                                 in turn, mismatched arrays, unknown and missing joint names,
                                 zero and backwards stamps, absurd set points) with the valid ones
  clock_rate [Hz] 0              > 0 (with /use_sim_time true): this fixture is the simulation
                                 and publishes /clock, from 0, in steps of 1 / clock_rate s paced
                                 at real time (or real_time_factor of it), as the plant node does
                                 (sim/nodes/plant_node.cpp):
                                 a stalled fixture stalls the clock, and a lag above 0.5 s is
                                 dropped, not caught up; every time of the run is then this clock's
  real_time_factor [-] 1.0       with clock_rate: the clock advances at this fraction of the
                                 wall clock's pace (0.25: 4 ms of wall time per simulated ms),
                                 so the node and the test, which this clock does not wait for,
                                 have that much more time for each step on a loaded host
Joint names are published in a non-standard order (rear first) with an extra joint, so
that the node must look them up by name.
"""
import itertools
import math
import threading
import time

import rospy
from geometry_msgs.msg import Twist
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu, JointState

JOINTS = ["rear_right_wheel", "front_left_wheel", "extra_caster_joint", "rear_left_wheel", "front_right_wheel"]
BAD_VALUES = [float("nan"), float("inf"), float("-inf")]


class SyntheticSensors:
    def __init__(self):
        p = lambda name, default: rospy.get_param("~" + name, default)
        self.rate = float(p("rate", 50.0))
        self.imu_offset = float(p("imu_offset", 0.007))
        self.wheel_speed = float(p("wheel_speed", 0.0))
        self.gyro_z = float(p("gyro_z", 0.0))
        self.accel = (float(p("accel_x", 0.0)), float(p("accel_y", 0.0)))
        self.set_point = (float(p("set_point_linear", 0.5)), float(p("set_point_angular", 0.0)))
        self.set_point_rate = float(p("set_point_rate", 20.0))
        self.start_delay = float(p("start_delay", 0.5))
        self.sensors_window = (float(p("sensors_stop_at", -1.0)), float(p("sensors_resume_at", -1.0)))
        self.set_point_window = (float(p("set_point_stop_at", -1.0)), float(p("set_point_resume_at", -1.0)))
        self.faults = bool(p("faults", False))
        self.clock_rate = float(p("clock_rate", 0.0))
        self.real_time_factor = float(p("real_time_factor", 1.0))
        if not (math.isfinite(self.real_time_factor) and 0.0 < self.real_time_factor <= 1.0):
            raise ValueError("~real_time_factor must be in (0, 1], not %r" % self.real_time_factor)

        self.joint_pub = rospy.Publisher("/joint_states", JointState, queue_size=50)
        self.imu_pub = rospy.Publisher("/imu/data", Imu, queue_size=50)
        self.set_point_pub = rospy.Publisher("/jackal_AIC/set_point", Twist, queue_size=50)
        self.joint_faults = itertools.cycle(self.make_joint_faults())
        self.imu_faults = itertools.cycle(self.make_imu_faults())
        self.set_point_faults = itertools.cycle(self.make_set_point_faults())
        self.t0 = None

    # ---- valid messages -------------------------------------------------------------
    def joint_state(self, stamp):
        msg = JointState()
        msg.header.stamp = stamp
        msg.name = list(JOINTS)
        n = len(JOINTS)
        # The wheels travel at their speed (a turning wheel with a constant position is a frozen
        # stream, which the node refuses: include/jackal_aic/safety/frozen_joint_states.hpp).
        travel = self.wheel_speed * stamp.to_sec()
        msg.position = [0.1 * i + travel for i in range(n)]
        msg.velocity = [self.wheel_speed] * n
        msg.effort = [0.5] * n
        return msg

    def imu(self, stamp):
        msg = Imu()
        msg.header.stamp = stamp
        msg.header.frame_id = "imu_link"
        msg.orientation.w = 1.0
        msg.angular_velocity.z = self.gyro_z
        msg.linear_acceleration.x, msg.linear_acceleration.y = self.accel
        msg.linear_acceleration.z = 9.81
        return msg

    def twist(self):
        msg = Twist()
        msg.linear.x, msg.angular.z = self.set_point
        return msg

    # ---- invalid messages (functions of the current stamp) ----------------------------
    def make_joint_faults(self):
        faults = []
        for field in ("position", "velocity", "effort"):
            for joint in range(len(JOINTS)):
                for bad in BAD_VALUES:
                    def f(stamp, field=field, joint=joint, bad=bad):
                        msg = self.joint_state(stamp)
                        getattr(msg, field)[joint] = bad
                        return msg
                    faults.append(f)

        def short_velocity(stamp):
            msg = self.joint_state(stamp)
            msg.velocity = msg.velocity[:-1]
            return msg

        def long_position(stamp):
            msg = self.joint_state(stamp)
            msg.position = msg.position + [0.0]
            return msg

        def empty_everything(stamp):
            msg = JointState()
            msg.header.stamp = stamp
            return msg

        def unknown_names(stamp):
            msg = self.joint_state(stamp)
            msg.name = ["wheel_%d" % i for i in range(len(JOINTS))]
            return msg

        def missing_joint(stamp):
            msg = self.joint_state(stamp)
            i = msg.name.index("rear_left_wheel")
            for field in ("name", "position", "velocity", "effort"):
                getattr(msg, field).pop(i)
            return msg

        def zero_stamp(stamp):
            return self.joint_state(rospy.Time(0))

        def backwards_stamp(stamp):
            return self.joint_state(stamp - rospy.Duration(1.0))

        faults += [short_velocity, long_position, empty_everything, unknown_names, missing_joint, zero_stamp,
                   backwards_stamp]
        return faults

    def make_imu_faults(self):
        faults = []
        fields = [("orientation", a) for a in "xyzw"] + [("angular_velocity", a) for a in "xyz"] + \
                 [("linear_acceleration", a) for a in "xyz"]
        for (part, axis) in fields:
            for bad in BAD_VALUES:
                def f(stamp, part=part, axis=axis, bad=bad):
                    msg = self.imu(stamp)
                    setattr(getattr(msg, part), axis, bad)
                    return msg
                faults.append(f)
        for cov in ("orientation_covariance", "angular_velocity_covariance", "linear_acceleration_covariance"):
            for bad in BAD_VALUES:
                def f(stamp, cov=cov, bad=bad):
                    msg = self.imu(stamp)
                    values = list(getattr(msg, cov))
                    values[0] = bad
                    values[8] = bad
                    setattr(msg, cov, values)
                    return msg
                faults.append(f)
        faults.append(lambda stamp: self.imu(rospy.Time(0)))
        faults.append(lambda stamp: self.imu(stamp - rospy.Duration(1.0)))
        return faults

    def make_set_point_faults(self):
        faults = []
        for part in ("linear", "angular"):
            for axis in "xyz":
                for bad in BAD_VALUES:
                    def f(part=part, axis=axis, bad=bad):
                        msg = self.twist()
                        setattr(getattr(msg, part), axis, bad)
                        return msg
                    faults.append(f)
        for (lin, ang) in ((1e9, 0.0), (-1e308, 1e308), (0.0, -1e9)):
            def f(lin=lin, ang=ang):
                msg = Twist()
                msg.linear.x, msg.angular.z = lin, ang
                return msg
            faults.append(f)
        return faults

    # ---- loops ----------------------------------------------------------------------
    def clock_loop(self, pub):
        """Publish /clock from 0 in steps of 1 / clock_rate s at real_time_factor x the wall
        clock's pace; a lag above 0.5 s of this clock is dropped (the clock stalls with the
        fixture), as the plant node does."""
        step = 1.0 / self.clock_rate  # simulated s per step
        wall_step = step / self.real_time_factor  # wall s per step
        n, base, sync = 0, 0, time.monotonic()
        while not rospy.core.is_shutdown_requested():
            due = base + int((time.monotonic() - sync) / wall_step)
            if due > n + int(0.5 / step):
                base, sync = n, time.monotonic()  # behind: drop the lag
                continue
            while n < due:
                n += 1
                pub.publish(Clock(clock=rospy.Time.from_sec(n * step)))
            time.sleep(max(0.0, sync + (n + 1 - base) * wall_step - time.monotonic()))

    def active(self, window, t):
        stop, resume = window
        if stop < 0.0 or t < stop:
            return True
        return resume >= 0.0 and t >= resume

    def sensor_loop(self):
        rate = rospy.Rate(self.rate)
        while not rospy.is_shutdown():
            now = rospy.Time.now()
            t = (now - self.t0).to_sec()
            if self.active(self.sensors_window, t):
                self.joint_pub.publish(self.joint_state(now))
                if self.faults:
                    # a newer stamp than the valid message, so only the fault itself can make it invalid
                    self.joint_pub.publish(next(self.joint_faults)(now + rospy.Duration(0.001)))
                rospy.sleep(self.imu_offset)
                stamp = now + rospy.Duration(self.imu_offset)
                self.imu_pub.publish(self.imu(stamp))
                if self.faults:
                    self.imu_pub.publish(next(self.imu_faults)(stamp + rospy.Duration(0.001)))
            try:
                rate.sleep()
            except rospy.ROSInterruptException:
                break

    def set_point_loop(self):
        rate = rospy.Rate(self.set_point_rate)
        while not rospy.is_shutdown():
            t = (rospy.Time.now() - self.t0).to_sec()
            if self.active(self.set_point_window, t):
                if self.faults:
                    self.set_point_pub.publish(next(self.set_point_faults)())
                self.set_point_pub.publish(self.twist())
            try:
                rate.sleep()
            except rospy.ROSInterruptException:
                break

    def run(self):
        rospy.sleep(self.start_delay)
        self.t0 = rospy.Time.now()
        threading.Thread(target=self.set_point_loop, daemon=True).start()
        self.sensor_loop()


if __name__ == "__main__":
    rospy.init_node("synthetic_sensors")
    sensors = SyntheticSensors()
    if sensors.clock_rate > 0.0:
        clock_pub = rospy.Publisher("/clock", Clock, queue_size=10)
        threading.Thread(target=sensors.clock_loop, args=(clock_pub,), daemon=True).start()
    sensors.run()

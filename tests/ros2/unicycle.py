"""A ROS 2 robot for the tests, written for them: a unicycle in a square room.

    tools/ros2-env PORT-BASE python3 tests/ros2/unicycle.py --namespace /NS \
        [--cmd-vel twist|stamped] [--pose X Y H] [--half MM] [--battery VOLTS]

It integrates the newest cmd_vel (linear.x, angular.z) at 50 Hz, with no
noise and no walls to stop it, and publishes what a real base's drivers
would: nav_msgs/Odometry on odom (its true pose, in metres), a 360-beam
sensor_msgs/LaserScan on scan (the walls of the room, |x| and |y| up to
HALF mm, measured from its centre), and, if given, sensor_msgs/BatteryState
on battery_state.  SIGUSR1 stops its odometry for good, as a crashed
driver would; SIGUSR2 jams its wheels, or frees them again: jammed, it
does not move, and its odometry goes on saying so.  SIGHUP makes its
odometry come in bursts, or steady again: bursty, it holds its odometry back
for 0.9 s of every second, as a driver on a congested link would, while
the unicycle drives on.  It says `unicycle: ready`.
"""

import argparse
import math
import os
import signal
import threading
import time

import rclpy
from rclpy.qos import QoSProfile, qos_profile_sensor_data
from geometry_msgs.msg import Twist, TwistStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import BatteryState, LaserScan

BEAMS = 360


def wall_distance(x, y, a, half):
    """From (x, y) along angle a (radians), to the nearest wall of the room."""
    best = math.inf
    dx, dy = math.cos(a), math.sin(a)
    for d, p in ((dx, x), (dy, y)):
        if abs(d) > 1e-9:
            t = ((half if d > 0 else -half) - p) / d
            if t > 0:
                best = min(best, t)
    return best


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--namespace", required=True)
    p.add_argument("--cmd-vel", choices=("twist", "stamped"), default="stamped")
    p.add_argument("--pose", type=float, nargs=3, default=(0.0, 0.0, 0.0))
    p.add_argument("--half", type=float, default=3000.0)
    p.add_argument("--battery", type=float, default=None)
    args = p.parse_args()
    signal.signal(signal.SIGTERM, lambda *_: os._exit(0))
    rclpy.init()
    node = rclpy.create_node("unicycle", namespace=args.namespace)
    state = {"x": args.pose[0] / 1000, "y": args.pose[1] / 1000,
             "th": math.radians(args.pose[2]), "v": 0.0, "w": 0.0, "odom": True,
             "jammed": False, "bursty": False}
    lock = threading.Lock()

    def on_cmd(m):
        t = m.twist if args.cmd_vel == "stamped" else m
        with lock:
            state["v"], state["w"] = t.linear.x, t.angular.z

    node.create_subscription(TwistStamped if args.cmd_vel == "stamped" else Twist, "cmd_vel",
                             on_cmd, QoSProfile(depth=10))
    odom = node.create_publisher(Odometry, "odom", qos_profile_sensor_data)
    scan = node.create_publisher(LaserScan, "scan", qos_profile_sensor_data)
    battery = (node.create_publisher(BatteryState, "battery_state", qos_profile_sensor_data)
               if args.battery else None)
    signal.signal(signal.SIGUSR1, lambda *_: state.__setitem__("odom", False))
    signal.signal(signal.SIGUSR2, lambda *_: state.__setitem__("jammed", not state["jammed"]))
    signal.signal(signal.SIGHUP, lambda *_: state.__setitem__("bursty", not state["bursty"]))
    threading.Thread(target=rclpy.spin, args=(node,), daemon=True).start()
    print("unicycle: ready", flush=True)
    dt, k, next_at = 0.02, 0, time.monotonic()
    while True:
        with lock:
            if state["jammed"]:
                state["v"] = state["w"] = 0.0
            state["th"] += state["w"] * dt
            state["x"] += state["v"] * math.cos(state["th"]) * dt
            state["y"] += state["v"] * math.sin(state["th"]) * dt
            x, y, th = state["x"], state["y"], state["th"]
        stamp = node.get_clock().now().to_msg()
        if state["odom"] and not (state["bursty"] and k % 50 < 45):
            o = Odometry()
            o.header.stamp = stamp
            o.pose.pose.position.x, o.pose.pose.position.y = x, y
            o.pose.pose.orientation.z = math.sin(th / 2)
            o.pose.pose.orientation.w = math.cos(th / 2)
            odom.publish(o)
        k += 1
        if k % 5 == 0:
            s = LaserScan()
            s.header.stamp = stamp
            s.angle_min, s.angle_increment = -math.pi, 2 * math.pi / BEAMS
            s.angle_max = s.angle_min + s.angle_increment * (BEAMS - 1)
            s.range_min, s.range_max = 0.05, 20.0
            half = args.half / 1000
            s.ranges = [wall_distance(x, y, th + s.angle_min + i * s.angle_increment, half)
                        for i in range(BEAMS)]
            scan.publish(s)
        if battery and k % 50 == 0:
            b = BatteryState()
            b.header.stamp = stamp
            b.voltage = args.battery
            battery.publish(b)
        next_at += dt
        time.sleep(max(0.0, next_at - time.monotonic()))


if __name__ == "__main__":
    main()

"""The ROS 2 trip server's latencies, for bench/ros2 (make bench-ros2).

    tools/ros2-env PORT-BASE python3 bench/ros2_latency.py PORT-BASE ROUNDS

This process is the robot: a node under /bench that publishes odometry at
50 Hz, each message's x its publish time (seconds since the start, as
metres), and subscribes cmd_vel.  robot/ros2/trip_ros2.py serves it, a
child.  Each round, back to back:
  - command latency: `base vel TV 0` over trip, TV new each time, to the
    cmd_vel that carries it arriving here;
  - its floor: rclpy's own publish to receive, from a second context (a
    participant of its own) to this node, on the same host;
  - odometry age: `base reckon` answers an x, the publish time of the
    odometry it used; the age is the newest odometry's publish time when
    the answer arrives, less that.
Prints each round's figures, then the medians over the rounds.
"""

import math
import os
import statistics
import subprocess
import sys
import threading
import time

import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import QoSProfile, qos_profile_sensor_data
from geometry_msgs.msg import Twist, TwistStamped
from nav_msgs.msg import Odometry

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "robot", "ros2"))
from b14_face import Trip  # noqa: E402  a blocking trip client

SAMPLES = 60
top = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")


def percentile(xs, p):
    xs = sorted(xs)
    return xs[min(len(xs) - 1, int(round(p / 100 * (len(xs) - 1))))]


class Bench:
    def __init__(self, port):
        self.t0 = time.monotonic()
        self.node = rclpy.create_node("bench_robot", namespace="/bench")
        self.arrived = {}
        self.cond = threading.Condition()
        self.node.create_subscription(TwistStamped, "cmd_vel", self.on_cmd, QoSProfile(depth=50))
        self.node.create_subscription(Twist, "floor", self.on_floor, QoSProfile(depth=50))
        self.odom = self.node.create_publisher(Odometry, "odom", qos_profile_sensor_data)
        self.newest = 0.0
        ex = SingleThreadedExecutor()
        ex.add_node(self.node)
        threading.Thread(target=ex.spin, daemon=True).start()
        threading.Thread(target=self.publish_odom, daemon=True).start()
        # the floor's publisher: a context, and so a participant, of its own
        self.ctx = rclpy.Context()
        rclpy.init(context=self.ctx)
        self.other = rclpy.create_node("bench_floor", context=self.ctx)
        self.floor_pub = self.other.create_publisher(Twist, "/bench/floor", QoSProfile(depth=50))
        self.port = port

    def publish_odom(self):
        while True:
            o = Odometry()
            t = time.monotonic() - self.t0
            o.pose.pose.position.x = t
            o.pose.pose.orientation.w = 1.0
            self.odom.publish(o)
            self.newest = t
            time.sleep(0.02)

    def on_cmd(self, m):
        with self.cond:
            self.arrived[round(m.twist.linear.x * 1000.0, 1)] = time.monotonic()
            self.cond.notify_all()

    def on_floor(self, m):
        with self.cond:
            self.arrived[round(m.linear.x * 1000.0, 1)] = time.monotonic()
            self.cond.notify_all()

    def wait_for(self, key):
        with self.cond:
            self.cond.wait_for(lambda: key in self.arrived, timeout=5)
            return self.arrived.pop(key, None)


def main():
    base, rounds = int(sys.argv[1]), int(sys.argv[2])
    port = base + 190
    rclpy.init()
    b = Bench(port)
    server = subprocess.Popen(
        [sys.executable, os.path.join(top, "robot/ros2/trip_ros2.py"), "--name", "bench",
         "--port", str(port), "--namespace", "/bench", "--max-speed", "100000",
         "--lock-dir", os.path.join(os.environ.get("TMPDIR", "/tmp"), "bench-ros2-%d" % port)],
        stdout=subprocess.PIPE, text=True)
    try:
        for line in server.stdout:
            if line.startswith("trip-ros2: ready"):
                break
        else:
            sys.exit("bench: the trip server did not start")
        trip = Trip("127.0.0.1", port)
        trip.ask("open", "base")
        figures = {"p50": [], "p95": [], "floor-p50": [], "floor-p95": [], "age-p95": []}
        value = 0.0
        for r in range(rounds):
            cmd, floor, ages = [], [], []
            for i in range(SAMPLES):
                value += 1.0                    # mm/s, new each time
                sent = time.monotonic()
                trip.ask("base", "vel", "%.1f" % value, 0)
                got = b.wait_for(value)
                if got:
                    cmd.append(got - sent)
                value += 1.0
                t = Twist()
                t.linear.x = value / 1000.0
                sent = time.monotonic()
                b.floor_pub.publish(t)
                got = b.wait_for(value)
                if got:
                    floor.append(got - sent)
                x = trip.ask("base", "reckon")[0] / 1000.0
                ages.append(max(0.0, b.newest - x))
                time.sleep(0.005 * (i % 4))   # not in step with the odometry
            trip.ask("base", "stop")
            f = {"p50": percentile(cmd, 50), "p95": percentile(cmd, 95),
                 "floor-p50": percentile(floor, 50), "floor-p95": percentile(floor, 95),
                 "age-p95": percentile(ages, 95)}
            for k, v in f.items():
                figures[k].append(v)
            print("round: %d %s" % (r + 1, " ".join("%s=%.2fms" % (k, v * 1000)
                                                    for k, v in f.items())), flush=True)
        med = {k: statistics.median(v) * 1000 for k, v in figures.items()}
        print("bench: ros2-command-latency-p50 %.2f ms" % med["p50"])
        print("bench: ros2-command-latency-p95 %.2f ms" % med["p95"])
        print("bench: ros2-publish-floor-p50 %.2f ms" % med["floor-p50"])
        print("bench: ros2-publish-floor-p95 %.2f ms" % med["floor-p95"])
        print("bench: ros2-command-latency-p50-over-floor %.2f x"
              % (med["p50"] / med["floor-p50"]))
        print("bench: ros2-odom-age-p95 %.2f ms (the odometry's period: 20 ms)" % med["age-p95"])
    finally:
        server.terminate()
        server.wait()


if __name__ == "__main__":
    main()

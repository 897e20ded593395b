"""b14_face: the ROS 2 face of the simulator's B14s (docs/ros2.md).

    tools/ros2-env PORT-BASE python3 robot/ros2/b14_face.py [--cmd-vel twist|stamped] \
        NAME=HOST:PORT ...

For each robot NAME, whose trip server sim/b14 runs at HOST:PORT, a node
under the namespace /NAME that does what a ROS 2 robot's drivers do:
publishes nav_msgs/Odometry on odom (the B14's odometry), a 16-beam
sensor_msgs/LaserScan on scan (its sonar ring) and sensor_msgs/BatteryState
on battery_state, the boxes its fiducial finder sees as a
geometry_msgs/PoseArray on fiducials (each box's pose in the robot's frame,
its id in position.z), and drives the base from cmd_vel.  It is a trip client of
the simulator, as any address space is, so `make demo ROS2=1` reaches each
robot through address space -> trip -> trip_ros2 -> ROS 2 -> this -> trip
-> sim/b14.  Says `b14-face: ready` once every robot is served.
"""

import argparse
import math
import os
import signal
import socket
import time

import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import QoSProfile, qos_profile_sensor_data
from builtin_interfaces.msg import Time
from geometry_msgs.msg import Pose, PoseArray, Twist, TwistStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import BatteryState, LaserScan

import trip_frame

ODOM_HZ = 50
SONAR_EVERY = 5                 # odometry periods per scan: 10 Hz
BATTERY_EVERY = 50              # one a second


class Trip:
    """A blocking trip client of one simulated robot, used by the main
    loop only: each period's requests go out together, tagged, and their
    answers are read back in one round trip."""

    def __init__(self, host, port):
        self.sock = socket.create_connection((host, port), timeout=10)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.parser = trip_frame.Parser(65536)
        self.tag = 0
        self.frames = []

    def ask(self, *words):
        return self.ask_all([words])[0]

    def ask_all(self, requests):
        """The numbers each request answers, in order."""
        tags = []
        out = b""
        for words in requests:
            self.tag = self.tag % 999999998 + 1
            tags.append(str(self.tag))
            out += trip_frame.encode(" ".join([tags[-1]] + [str(w) for w in words]))
        self.sock.sendall(out)
        answers = {}
        while len(answers) < len(tags):
            while self.frames:
                reply = self.frames.pop(0).decode("latin-1").split(" ")
                if reply[0] in tags:
                    if reply[1] != "ok":
                        words = requests[tags.index(reply[0])]
                        raise RuntimeError("b14: %s: %s" % (" ".join(map(str, words)),
                                                            " ".join(reply)))
                    answers[reply[0]] = [float(w) for w in reply[2:]]
            if len(answers) == len(tags):
                break
            data = self.sock.recv(65536)
            if not data:
                raise ConnectionError("the simulator closed the connection")
            self.frames += [v for k, v in self.parser.feed(data) if k == "frame"]
        return [answers[t] for t in tags]


def quaternion(heading_deg):
    h = math.radians(heading_deg) / 2
    return math.sin(h), math.cos(h)


class Face:
    def __init__(self, node, name, host, port, stamped):
        self.node, self.name = node, name
        self.trip = Trip(host, port)
        for d in ("base", "sonar", "battery", "fiducial"):
            self.trip.ask("open", d)
        self.trip.ask("sonar", "start")
        ns = "/" + name
        self.odom = node.create_publisher(Odometry, ns + "/odom", qos_profile_sensor_data)
        self.scan = node.create_publisher(LaserScan, ns + "/scan", qos_profile_sensor_data)
        self.battery = node.create_publisher(BatteryState, ns + "/battery_state",
                                             qos_profile_sensor_data)
        self.fiducials = node.create_publisher(PoseArray, ns + "/fiducials",
                                               qos_profile_sensor_data)
        node.create_subscription(TwistStamped if stamped else Twist, ns + "/cmd_vel",
                                 self.on_cmd_vel, QoSProfile(depth=10))
        self.count = 0
        self.cmd = None                 # the newest cmd_vel not yet sent on

    def on_cmd_vel(self, m):
        """Kept for the next period to send on: a callback that waited for
        the simulator would hold up the next, and they would queue."""
        t = m.twist if isinstance(m, TwistStamped) else m
        self.cmd = ("base", "vel", "%.1f" % (t.linear.x * 1000.0),
                    "%.2f" % math.degrees(t.angular.z))

    def publish(self):
        cmd, self.cmd = self.cmd, None
        asks = ([cmd] if cmd else []) + [("time",), ("base", "reckon")]
        answers = self.trip.ask_all(asks)
        # Stamped with the simulator's clock, which runs at its own speed:
        # the robot's clock, as trip_ros2's `time` answers it.
        ms = int(answers[-2][0])
        now = Time(sec=ms // 1000, nanosec=(ms % 1000) * 1000000)
        x, y, th = answers[-1]
        o = Odometry()
        o.header.stamp = now
        o.header.frame_id = self.name + "/odom"
        o.child_frame_id = self.name + "/base_link"
        o.pose.pose.position.x, o.pose.pose.position.y = x / 1000.0, y / 1000.0
        o.pose.pose.orientation.z, o.pose.pose.orientation.w = quaternion(th)
        self.odom.publish(o)
        self.count += 1
        if self.count % SONAR_EVERY == 0:
            r = self.trip.ask("sonar", "read")
            s = LaserScan()
            s.header.stamp = now
            s.header.frame_id = self.name + "/base_link"
            s.angle_min, s.angle_increment = 0.0, math.pi / 8
            s.angle_max = s.angle_increment * 15
            s.range_min, s.range_max = 0.15, 6.5
            s.ranges = [v / 1000.0 for v in r]
            self.scan.publish(s)
            self.publish_fiducials(now)
        if self.count % BATTERY_EVERY == 1:
            volts, _ = self.trip.ask("battery", "read")
            b = BatteryState()
            b.header.stamp = now
            b.voltage = volts
            b.present = True
            self.battery.publish(b)


    def publish_fiducials(self, now):
        """The boxes the fiducial finder sees, in the robot's frame: each a
        pose, its id in position.z (docs/ros2.md)."""
        w = self.trip.ask("fiducial", "read")
        a = PoseArray()
        a.header.stamp = now
        a.header.frame_id = self.name + "/base_link"
        for i in range(int(w[0])):
            ident, rng, bearing, orientation = w[1 + 4 * i: 5 + 4 * i]
            p = Pose()
            p.position.x = rng / 1000.0 * math.cos(math.radians(bearing))
            p.position.y = rng / 1000.0 * math.sin(math.radians(bearing))
            p.position.z = float(ident)
            p.orientation.z, p.orientation.w = quaternion(orientation)
            a.poses.append(p)
        self.fiducials.publish(a)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--cmd-vel", choices=("twist", "stamped"), default="stamped")
    p.add_argument("robots", nargs="+", metavar="NAME=HOST:PORT")
    args = p.parse_args()
    signal.signal(signal.SIGTERM, lambda *_: os._exit(0))
    signal.signal(signal.SIGINT, lambda *_: os._exit(0))
    rclpy.init()
    node = rclpy.create_node("murdoch_b14_face")
    faces = []
    for r in args.robots:
        name, address = r.split("=", 1)
        host, port = address.rsplit(":", 1)
        faces.append(Face(node, name, host, int(port), args.cmd_vel == "stamped"))
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    print("b14-face: ready", flush=True)
    period = 1.0 / ODOM_HZ
    next_at = time.monotonic()
    while True:
        for f in faces:
            f.publish()
        next_at += period
        # cmd_vel's callbacks run here, on this one thread, until the next
        # period: beside an executor's own threads this loop stalled for up
        # to 4 s at a time (docs/ros2.md).
        while next_at > time.monotonic():
            executor.spin_once(timeout_sec=max(0.0, next_at - time.monotonic()))


if __name__ == "__main__":
    main()

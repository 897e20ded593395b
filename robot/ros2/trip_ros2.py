"""trip_ros2: the trip server of one ROS 2 robot (docs/ros2.md).

    tools/ros2-env PORT-BASE python3 robot/ros2/trip_ros2.py --name NAME \
        --port PORT [--host ADDR] [--namespace /NS] [--cmd-vel twist|stamped] \
        [--odom TOPIC] [--scan TOPIC | --range TOPIC ...] [--battery TOPIC] \
        [--lock-dir DIR] [--appear-timeout S]

It serves the protocol of docs/trip-protocol.md, as sim/b14 does for a
simulated B14 (the same framing, errors, tags, device locks and `time`),
and drives the robot through ROS 2's standard messages:

    base      geometry_msgs/Twist or TwistStamped out on cmd_vel; the pose
              from nav_msgs/Odometry; translate, rotate and goto a closed
              loop here on odometry, held still while odometry is older
              than odom-stale seconds, stalled when odometry does not move
              for stall seconds of the robot's clock (its odometry's
              stamps) or stops for odom-timeout seconds
    sonar     sensor_msgs/LaserScan folded into the B14's 16 sectors, or
              sensor_msgs/Range topics, one per sonar
    battery   sensor_msgs/BatteryState
    fiducial  geometry_msgs/PoseArray on fiducials: each marker's pose in the
              robot's frame, its id in position.z (as robot/ros2/b14_face.py
              publishes the simulator's fiducial finder)
    who       NAME ros2

A device the robot lacks answers `unknown`.  It says `trip-ros2: NAME trip
HOST:PORT`, then `trip-ros2: ready` once the robot's node is there (its
odometry published, its cmd_vel subscribed, with the type it was told);
one that does not appear within the appear timeout is an ERROR line that
names the robot and the topic, and exit 1.
"""

import argparse
import fcntl
import math
import os
import selectors
import signal
import socket
import sys
import threading
import time

import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import QoSProfile, qos_profile_sensor_data
from geometry_msgs.msg import PoseArray, Twist, TwistStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import BatteryState, LaserScan, Range

import trip_frame

DEVICES = ("base", "sonar", "ir", "bumpers", "skirt", "buttons", "lights",
           "speech", "battery", "fiducial")
SONARS = 16
MAX_AWAITS = 8
MAX_FRAME_ERRORS = 16
MAX_BACKLOG = 65536
READ_SLICE = 16384
TICK = 0.02                     # seconds between steps of the controller
STEER_MM = 60                   # a goto steers while farther than this from its point
REFACE_DEG = 45                 # ... and faces it again when it is this far off its bearing
KEEP_ALIVE = 0.1                # seconds between repeats of an unchanged cmd_vel
CMD_VEL_TYPES = {"twist": "geometry_msgs/msg/Twist",
                 "stamped": "geometry_msgs/msg/TwistStamped"}


class TripError(Exception):
    def __init__(self, code, text):
        super().__init__(text)
        self.code, self.text = code, text


def say(name, *words):
    print("trip-ros2: " + name + ": " + " ".join(str(w) for w in words), flush=True)


def wrap180(a):
    a = math.fmod(a, 360.0)
    if a > 180:
        a -= 360
    elif a <= -180:
        a += 360
    return a


def approach(left, gain, floor, limit):
    """As sim/world.c's: proportional with a floor, so a motion ends
    rather than creeps."""
    return math.copysign(min(max(abs(left) * gain, floor), limit), left)


def angle_text(a, digits):
    """a in (-180, 180] as printed, as sim/trip.c's put_angle."""
    t = "%.*f" % (digits, wrap180(a))
    if t.startswith("-") and set(t[1:]) <= set("0."):
        return t[1:]
    if t.startswith("-180.") and set(t[5:]) <= {"0"}:
        return t[1:]
    return t


def topic(namespace, name):
    if name.startswith("/"):
        return name
    return namespace.rstrip("/") + "/" + name if namespace not in ("", "/") else "/" + name


# ---- the robot, as its topics show it -----------------------------------

class Robot:
    """The ROS 2 side: what the robot's topics say, and its cmd_vel."""

    def __init__(self, args):
        self.args = args
        self.node = rclpy.create_node("murdoch_trip_" + args.name.replace("-", "_"))
        ns = args.namespace
        self.cmd_vel_topic = topic(ns, args.cmd_vel_topic)
        self.odom_topic = topic(ns, args.odom)
        self.stamped = args.cmd_vel == "stamped"
        self.publisher = self.node.create_publisher(
            TwistStamped if self.stamped else Twist, self.cmd_vel_topic, QoSProfile(depth=10))
        self.lock = threading.Lock()
        self.sent = (None, 0.0)         # the last cmd_vel (tv, rv) and when
        self.odom = None                # (x mm, y mm, heading deg) as the robot has it
        self.odom_at = None             # monotonic seconds of the newest
        self.odom_count = 0
        self.odom_stamp_ms = 0
        self.node.create_subscription(Odometry, self.odom_topic, self._on_odom,
                                      qos_profile_sensor_data)
        self.sonar = None               # 16 ranges in mm, or None before any
        self.sonar_seq = 0
        self.sonar_topics = []
        if args.range:
            self.sonar_topics = [topic(ns, r) for r in args.range]
            self.ranges = [None] * len(args.range)
            for i, t in enumerate(self.sonar_topics):
                self.node.create_subscription(
                    Range, t, lambda m, i=i: self._on_range(i, m), qos_profile_sensor_data)
        elif args.scan:
            self.sonar_topics = [topic(ns, args.scan)]
            self.node.create_subscription(LaserScan, self.sonar_topics[0], self._on_scan,
                                          qos_profile_sensor_data)
        self.battery = None             # volts
        self.battery_topic = topic(ns, args.battery) if args.battery else None
        if self.battery_topic:
            self.node.create_subscription(BatteryState, self.battery_topic, self._on_battery,
                                          qos_profile_sensor_data)
        self.fiducials = None           # [(id, range mm, bearing, orientation)]
        self.fiducial_topic = topic(ns, args.fiducials) if args.fiducials else None
        if self.fiducial_topic:
            self.node.create_subscription(PoseArray, self.fiducial_topic, self._on_fiducials,
                                          qos_profile_sensor_data)
        self.executor = SingleThreadedExecutor()
        self.executor.add_node(self.node)
        threading.Thread(target=self._spin, daemon=True).start()

    def _spin(self):
        try:
            self.executor.spin()
        except Exception:                # shutdown
            pass

    def _on_odom(self, m):
        p, q = m.pose.pose.position, m.pose.pose.orientation
        heading = math.degrees(math.atan2(2 * (q.w * q.z + q.x * q.y),
                                          1 - 2 * (q.y * q.y + q.z * q.z)))
        with self.lock:
            self.odom = (p.x * 1000.0, p.y * 1000.0, heading)
            self.odom_stamp_ms = m.header.stamp.sec * 1000 + m.header.stamp.nanosec // 1000000
            self.odom_at = time.monotonic()
            self.odom_count += 1

    def _on_scan(self, m):
        """The scan folded into 16 sectors: sonar i faces 22.5 i degrees
        and reads the nearest valid range within its sector, else max."""
        far = self.args.sonar_max
        sectors = [far] * SONARS
        a = m.angle_min
        for r in m.ranges:
            if math.isfinite(r) and m.range_min <= r <= m.range_max:
                i = int(math.floor(wrap180(math.degrees(a)) / 22.5 + 0.5)) % SONARS
                sectors[i] = min(sectors[i], r * 1000.0)
            a += m.angle_increment
        with self.lock:
            self.sonar = [min(far, max(self.args.sonar_min, s)) for s in sectors]
            self.sonar_seq += 1

    def _on_range(self, i, m):
        r = m.range * 1000.0 if math.isfinite(m.range) else self.args.sonar_max
        with self.lock:
            self.ranges[i] = min(self.args.sonar_max, max(self.args.sonar_min, r))
            if all(x is not None for x in self.ranges):
                self.sonar = (self.ranges + [self.args.sonar_max] * SONARS)[:SONARS]
                self.sonar_seq += 1

    def _on_fiducials(self, m):
        seen = []
        for p in m.poses:
            q = p.orientation
            yaw = math.degrees(math.atan2(2 * (q.w * q.z + q.x * q.y),
                                          1 - 2 * (q.y * q.y + q.z * q.z)))
            seen.append((int(round(p.position.z)),
                         math.hypot(p.position.x, p.position.y) * 1000.0,
                         math.degrees(math.atan2(p.position.y, p.position.x)), yaw))
        with self.lock:
            self.fiducials = sorted(seen, key=lambda f: f[1])[:32]

    def _on_battery(self, m):
        with self.lock:
            self.battery = m.voltage

    def drive(self, tv, rv):
        """tv mm/s, rv deg/s, on cmd_vel: when they change, else every
        KEEP_ALIVE seconds, for drivers that stop a robot whose cmd_vel
        goes quiet; not every tick, which only queues up in a slow driver."""
        now = time.monotonic()
        if (tv, rv) == self.sent[0] and now - self.sent[1] < KEEP_ALIVE:
            return
        self.sent = ((tv, rv), now)
        t = Twist()
        t.linear.x = tv / 1000.0
        t.angular.z = math.radians(rv)
        if self.stamped:
            s = TwistStamped()
            s.header.stamp = self.node.get_clock().now().to_msg()
            s.twist = t
            t = s
        self.publisher.publish(t)

    def odom_age(self):
        """Seconds since the newest odometry came, or None before any."""
        with self.lock:
            at = self.odom_at
        return None if at is None else time.monotonic() - at

    def now_ms(self):
        """The robot's clock: its newest odometry's stamp, else this node's."""
        with self.lock:
            if self.odom is not None and self.odom_stamp_ms:
                return self.odom_stamp_ms
        return self.node.get_clock().now().nanoseconds // 1000000

    def appeared(self):
        """None once the robot is there, else the topic still waited for:
        its cmd_vel subscribed with our type, its odometry published."""
        subs = self.node.get_subscriptions_info_by_topic(self.cmd_vel_topic)
        if not subs:
            return "a subscriber of " + self.cmd_vel_topic
        self.check_cmd_vel_type(subs)
        if self.odom is None:
            return "odometry on " + self.odom_topic
        return None

    def check_cmd_vel_type(self, subs=None):
        subs = subs if subs is not None else self.node.get_subscriptions_info_by_topic(
            self.cmd_vel_topic)
        ours = CMD_VEL_TYPES[self.args.cmd_vel]
        theirs = sorted({s.topic_type for s in subs} - {ours})
        if theirs and not any(s.topic_type == ours for s in subs):
            other = [k for k, v in CMD_VEL_TYPES.items() if v == theirs[0]]
            raise SystemExit(
                "cmd_vel type mismatch on %s: the robot subscribes %s, this server was told "
                "to publish %s (the lab's (ros2 (cmd-vel %s)); %s)"
                % (self.cmd_vel_topic, theirs[0], ours, self.args.cmd_vel,
                   "write (cmd-vel %s)" % other[0] if other else "no trip mapping for it"))


# ---- the base's motions, a closed loop on odometry ------------------------

class Base:
    """Motions as sim/world.c's controllers have them, on odometry: the
    pose trip answers is the robot's odometry moved by set-position and
    set-heading."""

    def __init__(self, robot, args):
        self.robot, self.args = robot, args
        self.dx = self.dy = self.dth = 0.0      # trip frame = odometry turned dth, moved
        self.kind = "idle"                      # vel translate rotate goto idle
        self.tv = self.rv = 0.0
        self.stalled = 0
        self.goal = None
        self.turning = False                    # goto: still facing the goal
        self.progress = None                    # (robot's ms last looked, pose of the last progress)
        self.still = 0                          # robot's ms since that progress, that odometry covers

    def pose(self):
        with self.robot.lock:
            o = self.robot.odom
        if o is None:
            return (0.0, 0.0, 0.0)
        c, s = math.cos(math.radians(self.dth)), math.sin(math.radians(self.dth))
        return (o[0] * c - o[1] * s + self.dx, o[0] * s + o[1] * c + self.dy,
                wrap180(o[2] + self.dth))

    def set_position(self, x, y):
        px, py, _ = self.pose()
        self.dx += x - px
        self.dy += y - py

    def set_heading(self, h):
        px, py, th = self.pose()
        self.dth = wrap180(self.dth + h - th)
        nx, ny, _ = self.pose()
        self.dx += px - nx
        self.dy += py - ny

    def start(self, kind, goal=None):
        self.kind, self.goal, self.stalled = kind, goal, 0
        self.turning = kind == "goto"
        self.progress, self.still = (self.robot.now_ms(), self.pose()), 0
        if kind == "translate":
            x, y, th = self.pose()
            self.goal = (x, y, goal)
        elif kind == "rotate":
            self.goal = [goal, self.pose()[2]]          # left to turn, last heading
        self.step()

    def vel(self, tv, rv):
        self.kind, self.stalled = "vel", 0
        self.set(tv, rv)

    def stop(self):
        self.kind, self.goal = "idle", None
        self.set(0, 0)

    def set(self, tv, rv):
        a = self.args
        self.tv = max(-a.max_speed, min(a.max_speed, tv))
        self.rv = max(-a.max_turn, min(a.max_turn, rv))
        self.robot.drive(self.tv, self.rv)

    def moving(self):
        return self.kind != "idle"

    def step(self):
        """One tick of the controller: the next velocities, the end of a
        motion, or a stall."""
        if self.kind == "idle":
            return
        if self.kind == "vel":
            self.robot.drive(self.tv, self.rv)
            return
        x, y, th = self.pose()
        a = self.args
        why = self._stalled(x, y, th)
        if why:
            say(self.robot.args.name, "stalled in %s: %s" % (self.kind, why))
            self.stop()
            self.stalled = 1
            return
        if self.robot.odom_age() > a.odom_stale:
            # Not blind: a loop on old odometry drives past its goal and
            # hunts round it; held, the robot waits for the next.
            return self.robot.drive(0, 0)
        if self.kind == "translate":
            x0, y0, d = self.goal
            left = abs(d) - math.hypot(x - x0, y - y0)
            if left <= a.arrive_mm:
                return self.stop()
            self.set(math.copysign(min(a.speed, 2.0 * left + 20), d), 0)
        elif self.kind == "rotate":
            self.goal[0] -= wrap180(th - self.goal[1])
            self.goal[1] = th
            left = self.goal[0]
            if abs(left) <= a.arrive_deg:
                return self.stop()
            self.set(0, math.copysign(min(a.turn_speed, 2.0 * abs(left) + 3), left))
        elif self.kind == "goto":
            self.goto_step(x, y, th)

    def goto_step(self, x, y, th):
        """As sim/world.c's goto: face the goal, then close in along the
        heading, steering only while farther than 60 mm (so near it, it
        does not chase the bearing round), so that a robot ends a goto
        facing as the simulator's B14 does.  Farther out and more than 45
        degrees off its bearing (late odometry, a push), it faces the goal
        again: closing in along a heading beside the goal would end it
        there, its distance along the heading nil."""
        a = self.args
        gx, gy = self.goal
        dist = math.hypot(gx - x, gy - y)
        off = wrap180(math.degrees(math.atan2(gy - y, gx - x)) - th)
        if dist > STEER_MM and abs(off) > REFACE_DEG:
            self.turning = True         # past it, or off its line: face it again
        if self.turning and dist > 3 * a.arrive_mm and abs(off) > a.arrive_deg:
            return self.set(0, approach(off, 3, 1, a.turn_speed))
        self.turning = False
        along = dist * math.cos(math.radians(off))
        if abs(along) <= a.arrive_mm:
            return self.stop()
        steer = max(-a.turn_speed, min(a.turn_speed, 3 * off)) if dist > STEER_MM else 0
        self.set(approach(along, 3, 5, a.speed), steer)

    def _stalled(self, x, y, th):
        """Why the base is blocked, else None: odometry silent for
        odom-timeout seconds here, or not moving for stall seconds of the
        robot's own clock while the base is told to (its clock, so that a
        slow simulator or a loaded host is not taken for a blocked base).
        Only time its odometry covers counts: a gap in it longer than
        odom-stale says nothing of whether the robot moved."""
        silent = self.robot.odom_age()
        if silent is None or silent > self.args.odom_timeout:
            return "no odometry on %s for %.1f s" % (self.robot.odom_topic,
                                                     silent or self.args.odom_timeout)
        now = self.robot.now_ms()
        t, p0 = self.progress
        if math.hypot(x - p0[0], y - p0[1]) > 5 or abs(wrap180(th - p0[2])) > 1:
            self.progress, self.still = (now, (x, y, th)), 0
            return None
        if now - t <= 1000 * self.args.odom_stale:
            self.still += now - t
        self.progress = (now, p0)
        if self.still > 1000 * self.args.stall:
            return "not moved for %.1f s at %.0f %.0f %.1f" % (self.still / 1000, x, y, th)
        return None


# ---- trip: sessions and requests -------------------------------------------

class Session:
    def __init__(self, sock):
        self.sock = sock
        self.parser = None
        self.out = bytearray()
        self.locks = {}                 # device -> fd of its flock
        self.awaits = []
        self.stream = False
        self.errors = 0
        self.pending_since = None
        self.closed = False


class Server:
    def __init__(self, args, robot):
        self.args, self.robot = args, robot
        self.base = Base(robot, args)
        self.sessions = {}
        self.sonar_on = False
        self.streamed = 0
        os.makedirs(args.lock_dir, exist_ok=True)
        self.sel = selectors.DefaultSelector()
        self.listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self.listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.listener.bind((args.host, args.port))
        self.listener.listen(16)
        self.listener.setblocking(False)
        self.sel.register(self.listener, selectors.EVENT_READ, None)

    # the loop
    def run(self):
        next_tick = time.monotonic()
        while True:
            for key, ev in self.sel.select(max(0.0, next_tick - time.monotonic())):
                if key.data is None:
                    self.accept()
                else:
                    s = key.data
                    if ev & selectors.EVENT_READ:
                        self.readable(s)
                    if ev & selectors.EVENT_WRITE and not s.closed:
                        self.flush(s)
            now = time.monotonic()
            if now >= next_tick:
                next_tick = now + TICK
                self.tick(now)

    def tick(self, now):
        was = self.base.moving()
        self.base.step()
        if was and not self.base.moving():
            self.answer_awaits()
        self.stream_sonar()
        for s in list(self.sessions.values()):
            if s.pending_since and now - s.pending_since > self.args.stall_timeout:
                self.send(s, "0 err stalled incomplete frame for too long")
                self.flush(s)
                self.close(s)

    def accept(self):
        try:
            sock, _ = self.listener.accept()
        except OSError:
            return
        sock.setblocking(False)
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        s = Session(sock)
        s.parser = trip_frame.Parser(self.args.max_frame)
        self.sessions[sock.fileno()] = s
        self.sel.register(sock, selectors.EVENT_READ, s)

    def readable(self, s):
        try:
            data = s.sock.recv(READ_SLICE)
        except (BlockingIOError, InterruptedError):
            return
        except OSError:
            data = b""
        if not data:
            return self.close(s)
        for kind, value in s.parser.feed(data):
            if kind == "frame":
                reply = self.handle(s, value)
                if reply is not None:
                    self.send(s, reply)
            else:
                self.send(s, "0 err " + trip_frame.ERROR_TEXT[value])
                s.errors += 1
                if s.errors >= MAX_FRAME_ERRORS:
                    self.flush(s)
                    return self.close(s)
        s.pending_since = (s.pending_since or time.monotonic()) if s.parser.pending() else None
        self.flush(s)

    def send(self, s, payload):
        if s.closed:
            return
        s.out += trip_frame.encode(payload)
        if len(s.out) > MAX_BACKLOG:
            self.close(s)

    def flush(self, s):
        if s.closed:
            return
        try:
            n = s.sock.send(s.out)
            del s.out[:n]
        except (BlockingIOError, InterruptedError):
            pass
        except OSError:
            return self.close(s)
        self.sel.modify(s.sock, selectors.EVENT_READ | (selectors.EVENT_WRITE if s.out else 0), s)

    def close(self, s):
        if s.closed:
            return
        s.closed = True
        if "base" in s.locks:
            self.base.stop()
            self.answer_awaits()
        for d in list(s.locks):
            self.release(s, d)
        self.sel.unregister(s.sock)
        del self.sessions[s.sock.fileno()]
        s.sock.close()

    def answer_awaits(self):
        for s in self.sessions.values():
            for tag in s.awaits:
                self.send(s, "%s ok %s" % (tag, self.motion_end()))
            s.awaits = []
            self.flush(s)

    # locks, as sim/trip.c's: a flock per robot and device
    def acquire(self, s, d):
        if d in s.locks:
            return
        path = os.path.join(self.args.lock_dir, "%s.%s.lock" % (self.args.name, d))
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
        except OSError as e:
            raise TripError("held", "%s cannot be locked: %s" % (d, e.strerror))
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)
            raise TripError("held", "%s is held by another client" % d)
        s.locks[d] = fd

    def release(self, s, d):
        fd = s.locks.pop(d, None)
        if fd is not None:
            if d == "base":
                self.base.stop()
            os.close(fd)

    # requests
    def handle(self, s, payload):
        text = payload.decode("latin-1")
        words = [w for w in text.split(" ") if w]
        tag = words[0] if words else ""
        if len(words) < 2 or not (tag.isdigit() and 1 <= len(tag) <= 9 and int(tag) != 0):
            return "0 err syntax a request is TAG WORD ..., TAG a number 1 to 999999999"
        try:
            value = self.command(s, tag, words)
        except TripError as e:
            return "%s err %s %s" % (tag, e.code, e.text)
        if value is None:
            return None                         # a deferred await
        return "%s ok%s" % (tag, (" " + value) if value else "")

    def command(self, s, tag, words):
        verb = words[1]
        n = len(words)
        if verb == "ping" and n == 2:
            return "pong"
        if verb == "who" and n == 2:
            return self.args.name + " ros2"
        if verb == "time" and n == 2:
            return str(self.robot.now_ms())
        if verb in ("open", "close"):
            if n != 3 or words[2] not in DEVICES:
                raise TripError("unknown" if n == 3 else "args",
                                "%s takes one device name" % verb)
            d = words[2]
            if verb == "open":
                self.lacks(d)
                self.acquire(s, d)
            else:
                self.release(s, d)
            return ""
        if verb in DEVICES:
            return self.device(s, tag, verb, words[2:])
        raise TripError("unknown", "no command or device %.40s" % verb)

    def lacks(self, d):
        """Raises unknown for a device this robot has not: one trip_ros2 does
        not map, or one whose topics nothing publishes."""
        r = self.robot
        topics = {"base": [r.odom_topic], "sonar": r.sonar_topics,
                  "battery": [r.battery_topic] if r.battery_topic else [],
                  "fiducial": [r.fiducial_topic] if r.fiducial_topic else []}
        if d not in topics:
            raise TripError("unknown", "this robot has no %s (a ROS 2 robot: trip_ros2 maps"
                            " base, sonar, battery and fiducial)" % d)
        node = self.robot.node
        if not topics[d] or not all(node.get_publishers_info_by_topic(t) for t in topics[d]):
            raise TripError("unknown", "this robot has no %s: nothing publishes %s"
                            % (d, " ".join(topics[d]) or "a topic for it"))

    def device(self, s, tag, d, rest):
        if not rest:
            raise TripError("args", "%s needs a command" % d)
        if d not in s.locks:
            self.lacks(d)
        cmd, args = rest[0], rest[1:]
        table = {
            "base": {"vel": 2, "translate": 1, "rotate": 1, "goto": 2, "stop": 0,
                     "status": 0, "reckon": 0, "await": 0, "set-position": 2,
                     "set-heading": 1},
            "sonar": {"start": 0, "stop": 0, "read": 0, "stream": -1},
            "battery": {"read": 0, "tether": 1},
            "fiducial": {"read": 0},
        }[d]
        if cmd not in table:
            raise TripError("unknown", "%s has no command %.40s" % (d, cmd))
        if d not in s.locks:
            raise TripError("not-open", "open %s first" % d)
        want = table[cmd]
        if want == -1:
            if len(args) != 1:
                raise TripError("args", "%s %s takes one word" % (d, cmd))
        else:
            if len(args) != want:
                raise TripError("args", "%s %s takes %d number%s"
                                % (d, cmd, want, "" if want == 1 else "s"))
            nums = []
            for a in args:
                try:
                    v = float(a)
                except ValueError:
                    v = math.nan
                if not math.isfinite(v):
                    raise TripError("args", "%s is not a number" % a)
                nums.append(v)
            args = nums
        return getattr(self, ("%s_%s" % (d, cmd)).replace("-", "_"))(s, tag, *args)

    def reckon_text(self):
        x, y, th = self.base.pose()
        return "%.1f %.1f %s" % (x, y, angle_text(th, 2))

    def motion_end(self):
        return "%s %d" % (self.reckon_text(), self.base.stalled)

    def base_vel(self, s, tag, tv, rv):
        self.base.vel(tv, rv)
        return ""

    def base_translate(self, s, tag, d):
        self.base.start("translate", d)
        return ""

    def base_rotate(self, s, tag, a):
        self.base.start("rotate", a)
        return ""

    def base_goto(self, s, tag, x, y):
        self.base.start("goto", (x, y))
        return ""

    def base_stop(self, s, tag):
        self.base.stop()
        self.answer_awaits()
        return ""

    def base_status(self, s, tag):
        b = self.base
        moving = b.kind not in ("idle",) and not (b.kind == "vel" and b.tv == 0 and b.rv == 0)
        return "%s %.0f %.1f %d %d" % (self.reckon_text(), b.tv, b.rv, moving, b.stalled)

    def base_reckon(self, s, tag):
        return self.reckon_text()

    def base_await(self, s, tag):
        if not self.base.moving():
            return self.motion_end()
        if len(s.awaits) >= MAX_AWAITS:
            raise TripError("busy", "%d awaits are already pending" % MAX_AWAITS)
        s.awaits.append(tag)
        return None

    def base_set_position(self, s, tag, x, y):
        self.base.set_position(x, y)
        return ""

    def base_set_heading(self, s, tag, h):
        self.base.set_heading(h)
        return ""

    def sonar_start(self, s, tag):
        self.sonar_on = True
        return ""

    def sonar_stop(self, s, tag):
        self.sonar_on = False
        return ""

    def sonar_read(self, s, tag):
        """The newest reading; before any has come, a short wait for it."""
        deadline = time.monotonic() + 1.0
        while self.robot.sonar is None and time.monotonic() < deadline:
            time.sleep(0.01)
        with self.robot.lock:
            r = self.robot.sonar
        if r is None:
            raise TripError("unknown", "sonar: no reading from %s yet"
                            % " ".join(self.robot.sonar_topics))
        return " ".join("%.0f" % x for x in r)

    def sonar_stream(self, s, tag, word):
        if word not in ("on", "off"):
            raise TripError("args", "sonar stream takes on or off")
        s.stream = word == "on"
        return ""

    def stream_sonar(self):
        """Each new reading to the sessions that stream it, tag 0."""
        with self.robot.lock:
            seq, r = self.robot.sonar_seq, self.robot.sonar
        if seq == self.streamed or r is None:
            return
        self.streamed = seq
        for s in list(self.sessions.values()):
            if s.stream and "sonar" in s.locks:
                self.send(s, "0 sonar " + " ".join("%.0f" % x for x in r))
                self.flush(s)

    def battery_read(self, s, tag):
        with self.robot.lock:
            v = self.robot.battery
        if v is None:
            raise TripError("unknown", "battery: no BatteryState on %s yet"
                            % self.robot.battery_topic)
        return "%.2f 0" % v

    def fiducial_read(self, s, tag):
        with self.robot.lock:
            seen = self.robot.fiducials or []
        return " ".join([str(len(seen))] + ["%d %.0f %s %s" % (i, r, angle_text(b, 1),
                                                                angle_text(o, 1))
                                            for i, r, b, o in seen])

    def battery_tether(self, s, tag, on):
        raise TripError("unknown", "battery tether: a ROS 2 robot is plugged in by hand")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--name", required=True)
    p.add_argument("--host", default="127.0.0.1")
    p.add_argument("--port", type=int, required=True)
    p.add_argument("--namespace", default="")
    p.add_argument("--cmd-vel", choices=sorted(CMD_VEL_TYPES), default="stamped")
    p.add_argument("--cmd-vel-topic", default="cmd_vel")
    p.add_argument("--odom", default="odom")
    p.add_argument("--scan", default="scan")
    p.add_argument("--range", action="append", default=[])
    p.add_argument("--battery", default="battery_state")
    p.add_argument("--fiducials", default="fiducials")
    p.add_argument("--lock-dir", default=None)
    p.add_argument("--appear-timeout", type=float, default=20.0)
    p.add_argument("--stall", type=float, default=2.0)
    p.add_argument("--odom-timeout", type=float, default=5.0)
    p.add_argument("--odom-stale", type=float, default=0.25)
    p.add_argument("--stall-timeout", type=float, default=10.0)
    p.add_argument("--max-frame", type=int, default=1024)
    p.add_argument("--speed", type=float, default=400.0)
    p.add_argument("--turn-speed", type=float, default=60.0)
    p.add_argument("--max-speed", type=float, default=600.0)
    p.add_argument("--max-turn", type=float, default=120.0)
    p.add_argument("--arrive-mm", type=float, default=10.0)
    p.add_argument("--arrive-deg", type=float, default=0.5)
    p.add_argument("--sonar-min", type=float, default=150.0)
    p.add_argument("--sonar-max", type=float, default=6500.0)
    args = p.parse_args()
    if args.lock_dir is None:
        args.lock_dir = os.path.join(os.environ.get("TMPDIR", "/tmp"),
                                     "trip-ros2-locks-%d" % args.port)
    signal.signal(signal.SIGTERM, lambda *_: os._exit(0))
    signal.signal(signal.SIGINT, lambda *_: os._exit(0))
    rclpy.init()
    robot = Robot(args)
    try:
        server = Server(args, robot)
    except OSError as e:
        say(args.name, "ERROR: cannot listen on %s:%d: %s" % (args.host, args.port, e.strerror))
        sys.exit(1)
    print("trip-ros2: %s trip %s:%d pid %d" % (args.name, args.host, args.port, os.getpid()),
          flush=True)
    deadline = time.monotonic() + args.appear_timeout
    try:
        while True:
            waiting = robot.appeared()
            if waiting is None:
                break
            if time.monotonic() > deadline:
                say(args.name, "ERROR: the robot %s did not appear: waited %g s for %s (ROS_DOMAIN_ID %s)"
                    % (args.name, args.appear_timeout, waiting, os.environ.get("ROS_DOMAIN_ID", "0")))
                os._exit(1)
            time.sleep(0.05)
    except SystemExit as e:
        say(args.name, "ERROR: " + str(e))
        os._exit(1)
    print("trip-ros2: ready", flush=True)
    server.run()


if __name__ == "__main__":
    main()

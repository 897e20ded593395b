# Murdoch: `make demo` and `make test` do all the set-up on a fresh Debian
# machine (see README.md).

.PHONY: all deps native sim test bench bench-scale bench-sim bench-alloc bench-chaos bench-sched \
	bench-sched-scale bench-box \
	demo demo-box bench-ros2 clean

all: deps
	$(MAKE) native
	$(MAKE) -C sim all

# Installs what is missing: Debian packages, and Chibi-Scheme when there is
# none >= 0.10 on PATH.  Cheap when everything is there.
deps:
	tools/install-deps.sh

include lib/native.mk

test: all
	tests/run

bench: all
	bench/run

# Labs of 64, 128 and 256 address spaces (about ten minutes, 10 GB).
bench-scale: all
	bench/scale

bench-sim: all
	$(MAKE) -C sim bench

# Allocation: optimal assignment's speed, greedy's price, concurrent posers.
bench-alloc: all
	tools/chibi bench/alloc.scm

# Tasks that survive failure: random kills of robots under three posers
# (docs/tasks.md); MURDOCH_CHAOS_SECONDS, default 90.
bench-chaos: all
	tools/chibi bench/chaos.scm

bench-sched: all
	tools/chibi bench/sched.scm

# The box team on generated layouts (docs/box-move.md): BOX_RUNS (20)
# without a fault, BOX_FAULT_RUNS (10) with one, from seed BOX_SEED (1) on.
bench-box: all
	tools/chibi bench/box.scm

# The scheduler with thousands queued: 64 robots of 4 kinds, 8 posers,
# 2,500 tasks (bench/sched-scale.scm; sizes MURDOCH_SCHED_SCALE_*).
bench-sched-scale: all
	tools/chibi bench/sched-scale.scm

# Robots through ROS 2: trip command latency and odometry age beside
# rclpy's floor, the dual-sonar task through ROS 2 over straight (bench/ros2).
bench-ros2: all
	bench/ros2

# ROS2=1: every robot reached through ROS 2 (docs/ros2.md).
demo: all
	MURDOCH_ROS2=$(ROS2) bin/murdoch demo examples/tulane-lab.scm

# A team moves a box along a path (docs/box-move.md); FAULT=1 kills the
# inside pusher midway, FAULT=2 the other, and a spare takes its place.
demo-box: all
	MURDOCH_DEMO_TASK=examples/pose-box-move.scm \
	MURDOCH_DEMO_JUDGE=examples/box-judge.scm \
	MURDOCH_DEMO_FAULT=$(if $(filter 1,$(FAULT)),inside,$(if $(filter 2,$(FAULT)),outside)) \
	MURDOCH_ROS2=$(ROS2) bin/murdoch demo $(or $(BOX_LAB),examples/box-lab.scm)

clean: native-clean
	$(MAKE) -C sim clean

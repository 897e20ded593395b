# Sourced by bin/murdoch-lab and bin/murdoch-demo: whether a child runs.
#
# Not kill -0, which takes for the child whatever process the kernel gave
# its number once it was reaped: a shell reaps its children while it
# waits for a command, and a machine that forks a few hundred processes a
# second (two runs of the test suite) gives the number out again within a
# minute.  So a signal meant for the child could go to a stranger, and a
# script waiting for its child's end waited for the stranger's.  A child
# runs while /proc names its parent as the one it was forked by.

# Whether process PID runs as a child of PARENT; a zombie counts as
# running when ZOMBIES is "zombies", as one its parent has yet to reap.
child_running() {  # PID PARENT [ZOMBIES]
    read -r stat 2>/dev/null </proc/"$1"/stat || return 1
    parent=$2 zombies=${3:-}
    # shellcheck disable=SC2086  # the fields after the name, split
    set -- ${stat##*) }
    [ "$2" = "$parent" ] && { [ "$1" != Z ] || [ "$zombies" = zombies ]; }
}

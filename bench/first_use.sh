#!/usr/bin/env bash
# First use, measured as a new user meets it (issue 26's target table, bench/README.md):
# from a fresh clone in a temporary folder,
#
#   install       cargo install --locked --path .   (into a root of its own, not ~/.cargo)
#   crash_course  the first `ferroc run models/crash_course.xml` after the install
#   new_library   `ferroc new library x` + its first `ferroc run x/demo.xml`
#   edit          an edit of the module's code, and the run again
#   bundle        `ferroc bundle models/rescue_robot.xml` + `cargo build --release` in it
#
# Each step prints one line:  RESULT step wall_s cpu_s crates disk_mb
# (cpu_s: user + system time of every process of the step; crates: cargo's `Compiling`
# lines; disk_mb: what the step added on disk, in the folders it builds in), and every
# step but the install a `# STEP compiled: ...` line naming those crates, and every step
# a `# STEP load: ...` line (the load average at its end). Run it on an
# idle machine: it is not part of the test suite and takes a quarter of an hour or more.
#
# Options:
#   --steps a,b,...  only these steps (default: all five, in the order above)
#   --ferroc BIN     use this ferroc instead of the one the install step installs (for
#                    running steps without the install; its runners are built in its
#                    own cache: `BIN cache` says where)
#   --source DIR     the checkout to clone (default: the one holding this script; its
#                    committed HEAD is what is measured)
#   --keep           keep the temporary folder (printed) instead of removing it
#
# Example (proves the script without the long steps):
#   bench/first_use.sh --steps new_library,edit --ferroc target/debug/ferroc
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
source_dir="$(cd "$here/.." && pwd)"
steps="install,crash_course,new_library,edit,bundle"
ferroc=""
keep=0
while [ $# -gt 0 ]; do
    case "$1" in
        --steps) steps="$2"; shift 2 ;;
        --ferroc) ferroc="$(cd "$(dirname "$2")" && pwd)/$(basename "$2")"; shift 2 ;;
        --source) source_dir="$(cd "$2" && pwd)"; shift 2 ;;
        --keep) keep=1; shift ;;
        -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
        *) echo "first_use.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
    esac
done
wants() { [[ ",$steps," == *",$1,"* ]]; }
if [ -z "$ferroc" ] && ! wants install; then
    echo "first_use.sh: without the install step, name a ferroc with --ferroc BIN" >&2
    exit 2
fi

work="$(mktemp -d "${TMPDIR:-/tmp}/ferroc-first-use.XXXXXX")"
if [ "$keep" = 1 ]; then
    echo "# working in $work (kept)"
else
    trap 'rm -rf "$work"' EXIT
fi
clone="$work/ferroc"
git clone --quiet --no-hardlinks "$source_dir" "$clone"
echo "# clone of $(git -C "$clone" rev-parse --short HEAD) in $clone"
echo "# machine: $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg), $(rustc --version)"
echo "# step wall_s cpu_s crates disk_mb"

# Megabytes on disk under the given folders (missing ones count 0).
disk_mb() {
    local total=0 d
    for d in "$@"; do
        # (a file another build removes meanwhile is not an error)
        if [ -e "$d" ]; then total=$((total + $( { du -sm "$d" 2>/dev/null || true; } | cut -f1))); fi
    done
    echo "$total"
}

# measure STEP LOG DIRS... -- COMMAND...: runs COMMAND (its output in LOG), then prints
# the RESULT line; a failing command stops the script with its log.
measure() {
    local step="$1" log="$2"; shift 2
    local dirs=()
    while [ "$1" != "--" ]; do dirs+=("$1"); shift; done
    shift
    local before timing
    before="$(disk_mb "${dirs[@]}")"
    local TIMEFORMAT='%R %U %S'
    if ! timing="$( { time "$@" >"$log" 2>&1 ; } 2>&1 )"; then
        echo "first_use.sh: step $step failed; its output:" >&2
        tail -n 40 "$log" >&2
        exit 1
    fi
    local wall user sys crates after
    read -r wall user sys <<<"$timing"
    crates="$(grep -cE '^\s*Compiling ' "$log" || true)"
    after="$(disk_mb "${dirs[@]}")"
    printf 'RESULT %s %s %s %s %s\n' "$step" "$wall" "$(awk "BEGIN { printf \"%.1f\", $user + $sys }")" \
        "$crates" "$((after - before))"
    # The machine's load at the step's end: wall times are comparable only when idle.
    echo "# $step load: $(cut -d' ' -f1-3 /proc/loadavg)"
    # Which crates, in cargo's order (the install's list is long: not shown).
    if [ "$step" != install ] && [ "$crates" != 0 ]; then
        echo "# $step compiled: $(sed -nE 's/^\s*Compiling ([^ ]+) .*/\1/p' "$log" | tr '\n' ' ')"
    fi
}

cd "$clone"
if wants install; then
    measure install "$work/install.log" "$clone/target" -- \
        cargo install --locked --path . --root "$work/root"
    ferroc="$work/root/bin/ferroc"
    echo "# binary: $(du -m "$ferroc" | cut -f1) MB ($(stat -c %s "$ferroc") bytes)"
fi
cache="$("$ferroc" cache | sed -n 's/^cache: //p')"
echo "# runner cache: $cache"

# -v: cargo's lines, to count what was compiled.
if wants crash_course; then
    measure crash_course "$work/crash_course.log" "$cache" -- \
        "$ferroc" run models/crash_course.xml --lockstep --cycles 1 -q -v
fi
cd "$work"
if wants new_library || wants edit; then
    measure new_library "$work/new_library.log" "$cache" "$work/x" -- \
        sh -c "\"$ferroc\" new library x && \"$ferroc\" run x/demo.xml --lockstep --cycles 1 -q -v"
fi
if wants edit; then
    # The module's code changes (what it prints), then the run.
    sed -i 's/total = {:.2}/total is {:.2}/' x/src/lib.rs
    grep -q 'total is {:.2}' x/src/lib.rs || { echo "first_use.sh: the edit did not apply to x/src/lib.rs" >&2; exit 1; }
    measure edit "$work/edit.log" "$cache" -- \
        "$ferroc" run x/demo.xml --lockstep --cycles 1 -q -v
fi
if wants bundle; then
    "$ferroc" bundle "$clone/models/rescue_robot.xml" -o "$work/rescue" >/dev/null
    # As a user builds a bundle: in its own folder (CARGO_TARGET_DIR unset).
    measure bundle "$work/bundle.log" "$work/rescue" -- \
        env -u CARGO_TARGET_DIR cargo build --release --manifest-path "$work/rescue/Cargo.toml"
fi

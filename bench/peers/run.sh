#!/usr/bin/env bash
# Copper and dora-rs next to ferroc on the same benchmarks, on this machine, in one run
# (issue 32). Builds everything (release), then runs ferroc's counterpart and each peer
# in alternating rounds and prints one RESULT line per comparison:
#
#   RESULT peers-b2        five-stage ring, 4x4 f64: ferroc, hand loop, Copper (2 ways)
#   RESULT peers-b4-64B    64 B across processes: ferroc link, bare Zenoh, dora
#   RESULT peers-b4-6.2MB  6.2 MB frame across processes: ferroc (SHM / no SHM), bare
#                          Zenoh SHM, dora
#
# Usage: bench/peers/run.sh [--rounds N] [--quick] [--only LIST] [--no-build] [--out DIR]
#   --rounds N   alternating rounds (default 3); each figure is the median over rounds
#   --only LIST  comma-separated subset of b2,b4-64B,b4-6.2MB (default: all three)
#   --quick      fewer cycles/messages (a smoke run, minutes instead of ~10 min)
#   --no-build   use the binaries already built
#   --out DIR    keep every run's output there (default: a temporary folder)
#   --report DIR print the RESULT lines of a finished run's folder again (no run)
# Exit codes: 0 done, 1 a build or a run failed, 2 usage error.
#
# Peers, pinned: Copper cu29 =1.3.1 (bench/peers/copper-b2), dora-node-api =1.1.0 and
# the dora CLI/daemon 1.1.0 (`dora` on PATH if it is 1.1.0, else PyPI's dora-rs-cli
# ==1.1.0 in a venv under bench/peers/target, else `cargo install dora-cli@1.1.0`).
# Builds of the peers run under `nice -n 10` with -j 2: the machine may be shared.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
rounds=3 quick=0 build=1 out="" only="b2,b4-64B,b4-6.2MB" report=""
while [ $# -gt 0 ]; do
    case "$1" in
        --rounds) rounds=${2:-}; shift 2 || true ;;
        --quick) quick=1; shift ;;
        --no-build) build=0; shift ;;
        --only) only=${2:-}; shift 2 || true ;;
        --report) report=${2:-}; shift 2 || true ;;
        --out) out=${2:-}; shift 2 || true ;;
        -h|--help) sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        *) echo "run.sh: unknown option $1" >&2
           echo "help: bench/peers/run.sh [--rounds N] [--quick] [--only LIST] [--no-build] [--out DIR]" >&2
           exit 2 ;;
    esac
done
case "$rounds" in ''|*[!0-9]*|0) echo "run.sh: --rounds needs a whole number >= 1" >&2; exit 2 ;; esac
want() { case ",$only," in *",$1,"*) return 0 ;; *) return 1 ;; esac; }
for c in ${only//,/ }; do
    case "$c" in b2|b4-64B|b4-6.2MB) ;; *) echo "run.sh: --only: unknown comparison $c (b2, b4-64B, b4-6.2MB)" >&2; exit 2 ;; esac
done
if [ -n "$report" ]; then
    [ -d "$report" ] || { echo "run.sh: --report $report: no such folder" >&2; exit 2; }
    out=$report build=0
fi
[ -n "$out" ] || out=$(mktemp -d /tmp/ferroc-peers.XXXXXX)
mkdir -p "$out"

if [ "$quick" = 1 ]; then
    b2_cycles=2000000 copper_cycles=200000 copper_log_cycles=20000 b4_messages=2000 large_messages=60
else
    b2_cycles=10000000 copper_cycles=1000000 copper_log_cycles=100000 b4_messages=10000 large_messages=300
fi
DORA_VERSION=1.1.0
peers_target="$here/target"
ferroc_bench="$root/target/release/ferroc-bench"

note() { echo "run.sh: $*" >&2; }
die() { note "$*"; exit 1; }

# ---------------------------------------------------------------- builds
find_dora() {
    local d
    for d in "$(command -v dora || true)" "$peers_target/dora-venv/bin/dora" \
             "$peers_target/dora-cli/bin/dora"; do
        if [ -n "$d" ] && [ -x "$d" ] && "$d" --version 2>/dev/null | grep -q " $DORA_VERSION\$"; then
            echo "$d"; return 0
        fi
    done
    return 1
}

install_dora() {
    find_dora >/dev/null && return 0
    note "installing the dora CLI $DORA_VERSION (PyPI dora-rs-cli, else crates.io dora-cli)"
    if python3 -m venv "$peers_target/dora-venv" >/dev/null 2>&1 &&
       "$peers_target/dora-venv/bin/pip" install -q "dora-rs-cli==$DORA_VERSION" >&2; then
        return 0
    fi
    nice -n 10 cargo install --locked -j 2 --root "$peers_target/dora-cli" \
        dora-cli --version "=$DORA_VERSION" >&2
}

if [ -z "$report" ]; then
need_dora=0
if want b4-64B || want b4-6.2MB; then need_dora=1; fi
peer_crates="-p copper-b2"
if [ "$need_dora" = 1 ]; then peer_crates="$peer_crates -p dora-b4"; fi
if [ "$build" = 1 ]; then
    note "building the peers (release, nice -n 10, -j 2) in $here"
    # shellcheck disable=SC2086 # two words on purpose
    (cd "$here" && nice -n 10 cargo build --release -j 2 $peer_crates >&2) ||
        die "the peers' build failed"
    note "building ferroc-bench (release, nice -n 10, -j 2)"
    (cd "$root" && nice -n 10 cargo build --release -j 2 -p ferroc-bench >&2) ||
        die "ferroc-bench's build failed"
    if [ "$need_dora" = 1 ]; then
        install_dora || die "the dora CLI $DORA_VERSION could not be installed"
    fi
fi
bins="$ferroc_bench $peers_target/release/copper_ring_default $peers_target/release/copper_ring_quiet"
dora=""
if [ "$need_dora" = 1 ]; then
    dora=$(find_dora) || die "no dora CLI $DORA_VERSION (run without --no-build to install it)"
    bins="$bins $peers_target/release/dora_sender $peers_target/release/dora_receiver"
fi
for bin in $bins; do
    [ -x "$bin" ] || die "$bin is missing (run without --no-build)"
done

# ---------------------------------------------------------------- one run of each
# Each writes the run's whole output to $out/<name>.<round>.log and appends the
# figures it needs to $out/<name>.<key> (one line per round).
keep() { echo "$3" >> "$out/$1.$2"; }
kv() { sed -n "s/.*[ ]$2=\([^ ]*\).*/\1/p" "$1" | head -1; }

ferroc_b2() {
    local log="$out/ferroc-b2.$1.log"
    "$ferroc_bench" b2 --cycles "$b2_cycles" --rounds 1 > "$log" 2>&1 || die "ferroc b2 failed: $log"
    keep ferroc-b2 cps "$(kv "$log" cycles_per_s)"
    keep hand-b2 cps "$(kv "$log" baseline_cycles_per_s)"
}

# Copper: logging off, or its default logging with the log file on this machine's
# disk (the run's output folder) or on /dev/shm (RAM: Copper's own cost of logging).
copper_b2() { # $1 round, $2 quiet|disk|shm
    local log="$out/copper-$2.$1.log" bin=copper_ring_default cycles=$copper_log_cycles dir
    case "$2" in
        quiet) bin=copper_ring_quiet; cycles=$copper_cycles ;;
        disk) dir="$out" ;;
        shm) dir=/dev/shm ;;
    esac
    "$peers_target/release/$bin" --cycles "$cycles" --rounds 1 ${dir:+--log-dir "$dir"} \
        > "$log" 2>&1 || die "copper $2 failed: $log"
    keep "copper-$2" cps "$(kv "$log" cycles_per_s)"
}

ferroc_b4_64() {
    local log="$out/ferroc-b4-parts.$1.log"
    "$ferroc_bench" b4-parts --messages "$b4_messages" --rounds 2 > "$log" 2>&1 ||
        die "ferroc b4-parts failed: $log"
    keep ferroc-64 p50 "$(kv "$log" p50_us)"; keep ferroc-64 p99 "$(kv "$log" p99_us)"
    keep zenoh-64 p50 "$(kv "$log" zenoh_p50_us)"; keep zenoh-64 p99 "$(kv "$log" zenoh_p99_us)"
}

ferroc_b4_large() {
    local log="$out/ferroc-b4-large.$1.log" v
    "$ferroc_bench" b4-large --messages "$large_messages" --rounds 2 > "$log" 2>&1 ||
        die "ferroc b4-large failed: $log"
    for v in ferroc-shm ferroc-net zenoh-shm zenoh-net; do
        # "b4-large  6220800 B  ferroc-shm  p50 X  p99 Y  max Z µs  n=N"
        # ($5 == "p50": not the ratio line "... ferroc-shm / zenoh-shm p50 ...")
        keep "$v-large" p50 "$(awk -v v="$v" '$2 == 6220800 && $4 == v && $5 == "p50" { print $6 }' "$log")"
        keep "$v-large" p99 "$(awk -v v="$v" '$2 == 6220800 && $4 == v && $5 == "p50" { print $8 }' "$log")"
    done
}

# dora: one dataflow of two nodes (sender → receiver), run by `dora run` (the daemon
# in the CLI's process, no coordinator). The sender's shared-memory pool is raised
# to 64 MB (`shared_memory_pool_size`), as dora's node API says to do for large
# outputs (its 8 MB default holds one 6.2 MB frame and falls back to copies). The
# receiver's input queue holds 1000 values (`queue_size`, as dora's own benchmark
# sets it): with the default of 10 a reader descheduled for a millisecond on a busy
# machine loses values, where ferroc's reliable link makes the writer wait.
dora_b4() { # $1 round, $2 label, $3 size, $4 count, $5 gap_us, $6 warm-up
    local dir="$out/dora-$2.$1" log="$out/dora-$2.$1.log"
    mkdir -p "$dir"
    cat > "$dir/dataflow.yml" <<EOF
nodes:
  - id: sender
    path: $peers_target/release/dora_sender
    outputs:
      - value
    shared_memory_pool_size: 64MB
    env:
      DORA_B4_SIZE: "$3"
      DORA_B4_COUNT: "$4"
      DORA_B4_GAP_US: "$5"
      DORA_B4_WARM_UP: "$6"
  - id: receiver
    path: $peers_target/release/dora_receiver
    inputs:
      value:
        source: sender/value
        queue_size: 1000
    env:
      DORA_B4_COUNT: "$4"
      DORA_B4_WARM_UP: "$6"
      DORA_B4_OUT: "$dir/latency.txt"
EOF
    (cd "$dir" && timeout 600 "$dora" run dataflow.yml > "$log" 2>&1) || die "dora $2 failed: $log"
    [ -s "$dir/latency.txt" ] || die "dora $2: the receiver wrote no figures: $log"
    # latency.txt: "p50_us p99_us max_us n lost"
    read -r p50 p99 _max n lost < "$dir/latency.txt"
    keep "dora-$2" p50 "$p50"; keep "dora-$2" p99 "$p99"; keep "dora-$2" n "$n"
    keep "dora-$2" lost "$lost"
}

# ---------------------------------------------------------------- rounds
load_start=$(cut -d' ' -f1-3 /proc/loadavg)
note "$rounds rounds; output in $out; load average at the start: $load_start"
for r in $(seq 1 "$rounds"); do
    note "round $r of $rounds"
    # Alternate who goes first, so a busy moment of the machine hits each side alike.
    if [ $((r % 2)) = 1 ]; then
        if want b2; then ferroc_b2 "$r"; copper_b2 "$r" quiet; copper_b2 "$r" shm; copper_b2 "$r" disk; fi
        if want b4-64B; then ferroc_b4_64 "$r"; dora_b4 "$r" 64 64 "$b4_messages" 100 500; fi
        if want b4-6.2MB; then ferroc_b4_large "$r"; dora_b4 "$r" large 6220800 "$large_messages" 20000 20; fi
    else
        if want b2; then copper_b2 "$r" disk; copper_b2 "$r" shm; copper_b2 "$r" quiet; ferroc_b2 "$r"; fi
        if want b4-64B; then dora_b4 "$r" 64 64 "$b4_messages" 100 500; ferroc_b4_64 "$r"; fi
        if want b4-6.2MB; then dora_b4 "$r" large 6220800 "$large_messages" 20000 20; ferroc_b4_large "$r"; fi
    fi
done
load_end=$(cut -d' ' -f1-3 /proc/loadavg)
echo "$load_start" > "$out/load_start"; echo "$load_end" > "$out/load_end"
else
# --report: the figures of a finished run; its rounds are the lines of any figure file.
load_start=$(cat "$out/load_start" 2>/dev/null || echo unknown)
load_end=$(cat "$out/load_end" 2>/dev/null || echo unknown)
rounds=$(wc -l < "$(ls "$out"/*.p50 "$out"/*.cps 2>/dev/null | head -1)")
fi


# ---------------------------------------------------------------- results
median() { sort -g "$out/$1.$2" | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", a / b }'; }
sum() { awk '{ s += $1 } END { print s }' "$out/$1.$2"; }

if want b2; then
f=$(median ferroc-b2 cps) h=$(median hand-b2 cps)
cdisk=$(median copper-disk cps) cshm=$(median copper-shm cps) cq=$(median copper-quiet cps)
echo "RESULT peers-b2 ferroc_cycles_per_s=$f hand_loop_cycles_per_s=$h copper_logging_off_cycles_per_s=$cq copper_default_log_shm_cycles_per_s=$cshm copper_default_log_disk_cycles_per_s=$cdisk ferroc_vs_copper_logging_off=$(ratio "$f" "$cq") ferroc_vs_copper_default_shm=$(ratio "$f" "$cshm") ferroc_vs_copper_default_disk=$(ratio "$f" "$cdisk") hand_vs_ferroc=$(ratio "$h" "$f") ferroc_cycles=$b2_cycles copper_cycles=$copper_cycles copper_logged_cycles=$copper_log_cycles rounds=$rounds"
fi

if want b4-64B; then
fp=$(median ferroc-64 p50) f9=$(median ferroc-64 p99) zp=$(median zenoh-64 p50) z9=$(median zenoh-64 p99)
dp=$(median dora-64 p50) d9=$(median dora-64 p99)
echo "RESULT peers-b4-64B ferroc_p50_us=$fp ferroc_p99_us=$f9 zenoh_p50_us=$zp zenoh_p99_us=$z9 dora_p50_us=$dp dora_p99_us=$d9 dora_vs_ferroc_p50=$(ratio "$dp" "$fp") dora_vs_ferroc_p99=$(ratio "$d9" "$f9") ferroc_vs_zenoh_p50=$(ratio "$fp" "$zp") messages_per_round=$b4_messages dora_received=$(sum dora-64 n) dora_lost=$(sum dora-64 lost) gap_us=100 rounds=$rounds"
fi

if want b4-6.2MB; then
sp=$(median ferroc-shm-large p50) s9=$(median ferroc-shm-large p99)
np=$(median ferroc-net-large p50) n9=$(median ferroc-net-large p99)
zsp=$(median zenoh-shm-large p50) zs9=$(median zenoh-shm-large p99)
dp=$(median dora-large p50) d9=$(median dora-large p99)
echo "RESULT peers-b4-6.2MB ferroc_shm_p50_us=$sp ferroc_shm_p99_us=$s9 ferroc_net_p50_us=$np ferroc_net_p99_us=$n9 zenoh_shm_p50_us=$zsp zenoh_shm_p99_us=$zs9 dora_p50_us=$dp dora_p99_us=$d9 dora_vs_ferroc_shm_p50=$(ratio "$dp" "$sp") dora_vs_ferroc_shm_p99=$(ratio "$d9" "$s9") messages_per_round=$large_messages dora_received=$(sum dora-large n) dora_lost=$(sum dora-large lost) gap_us=20000 rounds=$rounds"
fi

echo "peers-machine: cpus=$(nproc) load_start=\"$load_start\" load_end=\"$load_end\" rustc=\"$(rustc --version | cut -d' ' -f2)\" copper=cu29-1.3.1 dora=$DORA_VERSION out=$out"

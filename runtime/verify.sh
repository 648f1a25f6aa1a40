#!/usr/bin/env bash
# Model checks of the port core and services (used by CI):
#   1. loom: every interleaving, up to a preemption bound, of the scenarios in
#      runtime/ports/tests/loom_ports.rs, loom_services.rs, loom_wakeup.rs,
#      loom_local.rs and loom_inline.rs
#      (LOOM_MAX_PREEMPTIONS, default 3; ~20 s).
#   2. Miri: undefined behaviour, data races and leaks in the unit tests of the port
#      core (cargo +nightly miri test -p ferroc-ports --lib port::), where every
#      unsafe block Miri can check lives (the others are FFI calls: thread placement
#      in ferroc-ports' thread.rs). Every other runtime crate forbids unsafe code. The
#      other unit tests run containers on wall clocks, which Miri's isolation refuses
#      (clock_gettime REALTIME) and which would take hours under it.
#      Miri needs a nightly toolchain. Where there is none (CI machines have only
#      the one stable toolchain and cannot fetch another) Miri is skipped with a
#      message; set VERIFY_REQUIRE_MIRI=1 to make that an error instead.
# Exits non-zero as soon as one fails.
set -euo pipefail
cd "$(dirname "$0")/.."

run() {
  echo "+ $*" >&2
  "$@"
}

echo "== loom (runtime/ports/tests/loom_ports.rs, loom_services.rs, loom_wakeup.rs, loom_local.rs, loom_inline.rs)" >&2
# A separate target dir: --cfg loom changes every fingerprint, and sharing target/
# would rebuild the normal build after each loom run.
run env RUSTFLAGS="--cfg loom" CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-target}/loom" \
  LOOM_MAX_PREEMPTIONS="${LOOM_MAX_PREEMPTIONS:-3}" \
  cargo test -p ferroc-ports --release --test loom_ports --test loom_services --test loom_wakeup --test loom_local --test loom_inline

echo "== miri (ferroc-ports unit tests of the port core)" >&2
if ! cargo +nightly miri --version >/dev/null 2>&1; then
  if [ "${VERIFY_REQUIRE_MIRI:-0}" = 1 ]; then
    echo "error: Miri is not installed (rustup toolchain install nightly --component miri)" >&2
    exit 1
  fi
  echo "verify.sh: loom passed; Miri SKIPPED: no nightly toolchain with Miri here" >&2
  exit 0
fi
run cargo +nightly miri test -p ferroc-ports --lib port::

echo "verify.sh: loom and Miri passed" >&2

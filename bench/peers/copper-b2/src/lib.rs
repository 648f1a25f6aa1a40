//! Benchmark B2 of ferroc (`bench/src/b2.rs`, `models/control_loop.xml`) on Copper:
//! five stages pass a 4×4 `f64` matrix around a ring, each adding 1 to element
//! (0, 0), one Copper task per stage, cycles back to back (no `rate_target_hz`).
//!
//! Copper runs one CopperList per cycle through an acyclic task graph: a source
//! starts the list, a sink ends it, and a connection cannot lead back to an earlier
//! task. The ring's closing edge (s5 → s1, one cycle later, what `delay="1"` says in
//! ferroc's model) therefore goes through [`LOOP_BACK`], a thread-local slot that
//! the sink writes and the source reads on the next cycle. Copper runs all tasks of
//! this graph on the thread that calls `run_one_iteration`, so the slot is a plain
//! `Cell` (about a nanosecond, less than any port of Copper's or ours).
//!
//! The binaries `copper_ring_default` and `copper_ring_quiet` differ only in their
//! RON configuration and logger; see their doc comments.

use cu29::prelude::*;
use std::cell::Cell;
use std::time::{Duration, Instant};

/// The matrix travelling around the ring (`f64[4][4]` in ferroc's model).
pub type Matrix = [[f64; 4]; 4];

thread_local! {
    /// The ring's closing edge: s5's output of the last cycle, s1's input of this one.
    pub static LOOP_BACK: Cell<Matrix> = const { Cell::new([[0.0; 4]; 4]) };
}

/// Stage s1: reads the matrix s5 published last cycle, adds 1, publishes.
#[derive(Reflect)]
pub struct First;
impl Freezable for First {}
impl CuSrcTask for First {
    type Resources<'r> = ();
    type Output<'m> = output_msg!(Matrix);
    fn new(_: Option<&ComponentConfig>, _: ()) -> CuResult<Self> {
        Ok(Self)
    }
    fn process(&mut self, _: &CuContext, output: &mut Self::Output<'_>) -> CuResult<()> {
        let mut matrix = LOOP_BACK.with(Cell::get);
        matrix[0][0] += 1.0;
        output.set_payload(matrix);
        Ok(())
    }
}

/// Stages s2 … s4: read the predecessor's matrix, add 1, publish.
#[derive(Reflect)]
pub struct Stage;
impl Freezable for Stage {}
impl CuTask for Stage {
    type Resources<'r> = ();
    type Input<'m> = input_msg!(Matrix);
    type Output<'m> = output_msg!(Matrix);
    fn new(_: Option<&ComponentConfig>, _: ()) -> CuResult<Self> {
        Ok(Self)
    }
    fn process(
        &mut self,
        _: &CuContext,
        input: &Self::Input<'_>,
        output: &mut Self::Output<'_>,
    ) -> CuResult<()> {
        let mut matrix = *input
            .payload()
            .ok_or("stage: no matrix from its predecessor")?;
        matrix[0][0] += 1.0;
        output.set_payload(matrix);
        Ok(())
    }
}

/// Stage s5: reads s4's matrix, adds 1, hands it back to s1 for the next cycle.
#[derive(Reflect)]
pub struct Last;
impl Freezable for Last {}
impl CuSinkTask for Last {
    type Resources<'r> = ();
    type Input<'m> = input_msg!(Matrix);
    fn new(_: Option<&ComponentConfig>, _: ()) -> CuResult<Self> {
        Ok(Self)
    }
    fn process(&mut self, _: &CuContext, input: &Self::Input<'_>) -> CuResult<()> {
        let mut matrix = *input.payload().ok_or("last stage: no matrix from s4")?;
        matrix[0][0] += 1.0;
        LOOP_BACK.with(|slot| slot.set(matrix));
        Ok(())
    }
}

/// `--cycles N --rounds R` (defaults: 2,000,000 and 3).
pub fn parse_args(args: &[String], default_cycles: u64) -> Result<(u64, u64), String> {
    let (mut cycles, mut rounds) = (default_cycles, 3);
    let mut it = args.iter();
    while let Some(flag) = it.next() {
        let value = it.next().ok_or(format!("{flag} needs a value"))?;
        let n: u64 = value
            .parse()
            .map_err(|_| format!("{flag}: not a whole number: {value}"))?;
        match flag.as_str() {
            "--cycles" if n > 0 => cycles = n,
            "--rounds" if n > 0 => rounds = n,
            _ => return Err(format!("unknown option or zero value: {flag} {value}")),
        }
    }
    Ok((cycles, rounds))
}

/// Runs `cycles` iterations with `iterate`, checks the matrix went round every
/// stage of every cycle, returns the time taken.
pub fn timed_round(
    cycles: u64,
    mut iterate: impl FnMut() -> CuResult<()>,
) -> Result<Duration, String> {
    let before = LOOP_BACK.with(Cell::get)[0][0];
    let start = Instant::now();
    for _ in 0..cycles {
        iterate().map_err(|e| format!("iteration failed: {e}"))?;
    }
    let took = start.elapsed();
    let after = LOOP_BACK.with(Cell::get)[0][0];
    let expected = before + 5.0 * cycles as f64;
    if after != expected {
        return Err(format!(
            "ring lost work: element (0,0) is {after}, expected {expected}"
        ));
    }
    Ok(took)
}

/// Prints the per-round lines and the `RESULT` line: best round (the least disturbed
/// by other load) and the median, as ferroc's b2 reports. `extra`: more `key=value`
/// words for the `RESULT` line (may be empty).
pub fn report(variant: &str, extra: &str, cycles: u64, rounds: &[Duration]) {
    let mut ns: Vec<f64> = rounds
        .iter()
        .map(|t| t.as_nanos() as f64 / cycles as f64)
        .collect();
    ns.sort_by(f64::total_cmp);
    let (best, median) = (ns[0], ns[ns.len() / 2]);
    println!(
        "copper-b2 {variant}: {best:.1} ns/cycle ({:.3} M cycles/s; median {median:.1} ns) over {} rounds of {cycles} cycles",
        1e3 / best,
        ns.len()
    );
    println!(
        "RESULT copper-b2 variant={variant} cycles_per_s={:.0} ns_per_cycle={best:.1} median_ns={median:.1} cycles={cycles} rounds={}{extra}",
        1e9 / best,
        ns.len()
    );
}

use super::*;
use crate::recording::ChannelInfo;

#[test]
fn missing_folders_are_accepted_and_created_when_the_recording_opens() {
    let dir = std::env::temp_dir().join(format!("ferroc-logger-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let path = dir.join("agv/trajectory.mcap");
    assert_eq!(check_log_path(&path), Ok(()));
    assert!(!dir.exists(), "checking creates nothing");
    let log = LogFile::open_shared(&path, 1).unwrap();
    // A second opener joins the same recording instead of truncating it.
    let again = LogFile::open_shared(&path, 1).unwrap();
    assert!(std::sync::Arc::ptr_eq(&log, &again));
    drop((log, again));
    let rec = recording::Recording::read(&path).unwrap();
    assert!(rec.finished && rec.damaged.is_none() && rec.messages.is_empty());
    // A file where a folder should be is refused when checked.
    let e = check_log_path(&path.join("x.mcap")).unwrap_err();
    assert!(e.contains("is not a folder"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The cost per message of recording a 100 Hz stream of 4×4 matrices, in the
/// logging container (encoding, JSON mirror, the shared file's lock, chunk writes and
/// the flush once per second of log time). A figure, not an assertion: run
/// `cargo test --release -p ferroc-std logging_cost -- --ignored --nocapture`.
#[test]
#[ignore]
fn logging_cost_of_a_100_hz_matrix_stream() {
    use ferroc_runtime::module::ValueTable;
    use ferroc_runtime::port::ConnectOptions;
    let table = ValueTable::default();
    let vt = table.get("f64[4][4]").expect("registered");
    let dir = std::env::temp_dir().join(format!("ferroc-logcost-{}", std::process::id()));
    for json in [true, false] {
        let (out, oh) = vt.output("out");
        let (input, ih) = vt.input("in/0", None);
        oh.connect(&ih, ConnectOptions::default()).unwrap();
        let info = ChannelInfo {
            topic: "bench/matrix".into(),
            model_type: "f64[4][4]".into(),
            ..ChannelInfo::default()
        };
        let mut ports = vec![Recorded::new(input, *vt.wire().unwrap(), info)];
        let path = dir.join(format!("matrix-{json}.mcap"));
        let log = LogFile::open_shared(&path, 1_000_000_000).unwrap();
        let (mut exact, mut text) = (Vec::new(), Vec::new());
        let n = 30_000u64;
        let mut spent = std::time::Duration::ZERO;
        for k in 0..n {
            let mut m = [[0.0f64; 4]; 4];
            m[k as usize % 4][k as usize % 3] = k as f64 * 0.001;
            m[3][3] = 1.0;
            out.typed::<[[f64; 4]; 4]>().unwrap().publish(m);
            // 100 Hz of log time, so the once-a-second flush happens as it would.
            let now = k * 10_000_000;
            let started = std::time::Instant::now();
            record_at(&log, &mut ports, now, json, &mut exact, &mut text).unwrap();
            spent += started.elapsed();
        }
        drop(log);
        let rec = recording::Recording::read(&path).unwrap();
        assert_eq!(rec.messages.len() as u64, if json { 2 * n } else { n });
        println!(
            "json mirror {json}: {:.2} µs per message ({n} messages, {} bytes)",
            spent.as_secs_f64() * 1e6 / n as f64,
            std::fs::metadata(&path).unwrap().len()
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

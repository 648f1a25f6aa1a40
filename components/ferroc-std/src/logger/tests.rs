use super::*;

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

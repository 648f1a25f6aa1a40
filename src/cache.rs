//! `ferroc cache`: where the runners of libraries are built, how much room it takes,
//! which runners it holds, and `--clean` to remove what ferroc put there.
//!
//! What `--clean` removes depends on whose folder it is (`runner/cache.rs`): a folder
//! ferroc made for itself (marked) is emptied whole; in any other (the checkout's
//! `target/`, a `CARGO_TARGET_DIR`) only the runners' own files go, because the
//! dependencies compiled there may be the developer's own builds; `cargo clean` there
//! removes everything.

use crate::runner::cache::{self, Cache, MARKER, PACKAGES, PROFILES};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(clap::Args)]
pub struct CacheArgs {
    /// Remove what ferroc put in the cache (the runners; in a folder ferroc made for
    /// itself, everything cargo compiled for them too)
    #[arg(long)]
    clean: bool,
    /// With --clean: list what would be removed, remove nothing
    #[arg(long, requires = "clean")]
    dry_run: bool,
}

pub fn run(args: CacheArgs) -> ExitCode {
    let cache = cache::locate();
    if args.clean {
        return clean(&cache, args.dry_run);
    }
    show(&cache);
    ExitCode::SUCCESS
}

/// Where, why there, how big, and each runner with its libraries and last build.
fn show(cache: &Cache) {
    println!("cache: {}", cache.dir.display());
    println!("  ({})", cache.origin_text());
    if !cache.dir.is_dir() {
        println!("size: nothing built yet");
        return;
    }
    let runners = runners(cache);
    let own: u64 = runners
        .iter()
        .flat_map(|r| runner_files(&cache.dir, &r.key))
        .map(|p| disk_usage(&p))
        .sum();
    let whose = if cache.is_dedicated() {
        "all of it ferroc's"
    } else {
        "shared with the other builds there"
    };
    println!(
        "size: {} in all ({whose}), {} of it the runners' own files",
        megabytes(disk_usage(&cache.dir)),
        megabytes(own)
    );
    if runners.is_empty() {
        println!("runners: none");
        return;
    }
    println!("runners: {}", runners.len());
    for r in &runners {
        let built: Vec<String> = PROFILES
            .iter()
            .filter(|p| {
                cache
                    .dir
                    .join(p)
                    .join(format!("ferroc-runner-{}", r.key))
                    .is_file()
            })
            .map(|p| p.to_string())
            .collect();
        let last = match crate::runner::build::read_record(&cache.dir.join(PACKAGES).join(&r.key)) {
            Some((kind, profile, seconds, compiled)) => format!(
                "; last build ({profile}, {kind}): {}, {compiled} crates compiled",
                crate::runner::build::duration(seconds)
            ),
            None => String::new(),
        };
        let state = if built.is_empty() {
            "not built".to_string()
        } else {
            format!("built ({})", built.join(", "))
        };
        println!("  {}  {}  {state}{last}", r.key, r.libraries);
    }
    println!("clean: ferroc cache --clean (--dry-run lists what it removes)");
}

struct Runner {
    key: String,
    /// The libraries it links (`libraries.txt`, written with the package).
    libraries: String,
}

/// The runner packages in the cache, by key.
fn runners(cache: &Cache) -> Vec<Runner> {
    let Ok(entries) = std::fs::read_dir(cache.dir.join(PACKAGES)) else {
        return Vec::new();
    };
    let mut out: Vec<Runner> = entries
        .flatten()
        .filter(|e| e.path().is_dir())
        .filter_map(|e| {
            let key = e.file_name().to_str()?.to_string();
            is_key(&key).then_some(key)
        })
        .map(|key| {
            let file = cache.dir.join(PACKAGES).join(&key).join("libraries.txt");
            let libraries = std::fs::read_to_string(file)
                .map(|t| t.trim().to_string())
                .unwrap_or_else(|_| "(libraries unknown)".into());
            Runner { key, libraries }
        })
        .collect();
    out.sort_by(|a, b| a.key.cmp(&b.key));
    out
}

/// A runner key: 16 lowercase hex digits (`program.rs`).
fn is_key(name: &str) -> bool {
    name.len() == 16
        && name
            .bytes()
            .all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b))
}

/// Whether a file name in `PROFILE/` (or its `deps/`, `.fingerprint/`, `incremental/`)
/// is cargo's output for a runner: `ferroc-runner-KEY…` or `ferroc_runner_KEY…`.
fn is_runner_output(name: &str) -> bool {
    ["ferroc-runner-", "ferroc_runner_"].iter().any(|prefix| {
        name.strip_prefix(prefix)
            .and_then(|rest| rest.get(..16))
            .is_some_and(is_key)
    })
}

/// The paths of one runner's own files (package and cargo's output for it).
fn runner_files(target: &Path, key: &str) -> Vec<PathBuf> {
    let mut out = vec![target.join(PACKAGES).join(key)];
    for profile in PROFILES {
        for sub in ["", "deps", ".fingerprint", "incremental", "build"] {
            let dir = target.join(profile).join(sub);
            let Ok(entries) = std::fs::read_dir(&dir) else {
                continue;
            };
            out.extend(entries.flatten().map(|e| e.path()).filter(|p| {
                p.file_name()
                    .and_then(|n| n.to_str())
                    .is_some_and(|n| is_runner_output(n) && n.contains(key))
            }));
        }
    }
    out
}

/// What `--clean` removes: everything but the marker in a folder ferroc made for
/// itself; else every runner's own files (including those of runners whose package is
/// gone) and the packages folder.
fn to_remove(cache: &Cache) -> Vec<PathBuf> {
    if cache.is_dedicated() {
        let Ok(entries) = std::fs::read_dir(&cache.dir) else {
            return Vec::new();
        };
        let mut all: Vec<PathBuf> = entries
            .flatten()
            .map(|e| e.path())
            .filter(|p| p.file_name().is_none_or(|n| n != MARKER))
            .collect();
        all.sort();
        return all;
    }
    let mut out = Vec::new();
    for profile in PROFILES {
        for sub in ["", "deps", ".fingerprint", "incremental", "build"] {
            let Ok(entries) = std::fs::read_dir(cache.dir.join(profile).join(sub)) else {
                continue;
            };
            out.extend(entries.flatten().map(|e| e.path()).filter(|p| {
                p.file_name()
                    .and_then(|n| n.to_str())
                    .is_some_and(is_runner_output)
            }));
        }
    }
    let packages = cache.dir.join(PACKAGES);
    if packages.is_dir() {
        out.push(packages);
    }
    out.sort();
    out
}

fn clean(cache: &Cache, dry_run: bool) -> ExitCode {
    let paths = to_remove(cache);
    let size: u64 = paths.iter().map(|p| disk_usage(p)).sum();
    let verb = if dry_run { "would remove" } else { "removing" };
    println!(
        "{verb} {} in {} ({} paths)",
        megabytes(size),
        cache.dir.display(),
        paths.len()
    );
    if !cache.is_dedicated() && cache.dir.is_dir() {
        println!(
            "  only the runners' own files: the dependencies compiled there are shared with the other builds in it ({}); `cargo clean` there removes everything",
            cache.origin_text()
        );
    }
    if dry_run {
        for p in &paths {
            println!("  {}", p.display());
        }
        return ExitCode::SUCCESS;
    }
    // cargo's lock of each profile folder: no build is running while we remove.
    let _locks: Vec<std::fs::File> = PROFILES
        .iter()
        .filter_map(|p| lock(&cache.dir.join(p)))
        .collect();
    let mut failed = false;
    for p in &paths {
        let removed = if p.is_dir() && !p.is_symlink() {
            std::fs::remove_dir_all(p)
        } else {
            std::fs::remove_file(p)
        };
        if let Err(e) = removed.or_else(|e| match e.kind() {
            std::io::ErrorKind::NotFound => Ok(()),
            _ => Err(e),
        }) {
            eprintln!("error: cannot remove {}: {e}", p.display());
            failed = true;
        }
    }
    if failed {
        eprintln!(
            "  help: check the folder's permissions, or remove it yourself when no ferroc runs"
        );
        return ExitCode::from(2);
    }
    println!("removed");
    ExitCode::SUCCESS
}

/// cargo's build lock of `dir` (`.cargo-lock`, an flock), taken (waiting for a running
/// build, said so), or `None` when there is none.
fn lock(dir: &Path) -> Option<std::fs::File> {
    let file = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .open(dir.join(".cargo-lock"))
        .ok()?;
    if file.try_lock().is_err() {
        eprintln!(
            "waiting for the build running in {} to finish",
            dir.display()
        );
        file.lock().ok()?;
    }
    Some(file)
}

/// Bytes on disk under `path` (allocated blocks, as `du` counts; links not followed).
pub fn disk_usage(path: &Path) -> u64 {
    let Ok(meta) = std::fs::symlink_metadata(path) else {
        return 0;
    };
    let own = {
        use std::os::unix::fs::MetadataExt;
        meta.blocks() * 512
    };
    if !meta.is_dir() {
        return own;
    }
    let children: u64 = std::fs::read_dir(path)
        .map(|entries| entries.flatten().map(|e| disk_usage(&e.path())).sum())
        .unwrap_or(0);
    own + children
}

fn megabytes(bytes: u64) -> String {
    let mb = bytes as f64 / 1_000_000.0;
    if mb >= 1000.0 {
        format!("{:.1} GB", mb / 1000.0)
    } else {
        format!("{mb:.0} MB")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runner_outputs_are_told_from_other_crates() {
        assert!(is_runner_output("ferroc-runner-0123456789abcdef"));
        assert!(is_runner_output("ferroc-runner-0123456789abcdef.d"));
        assert!(is_runner_output("ferroc_runner_0123456789abcdef-9f2c1a.d"));
        assert!(is_runner_output("ferroc-runner-0123456789abcdef-9f2c1a"));
        for other in [
            "ferroc-0123456789abcdef",
            "ferroc-runner",
            "ferroc-runner-xyz",
            "ferroc-runner-0123456789ABCDEF",
            "ferroc_host-9f2c1a",
            "my-ferroc-runner-0123456789abcdef",
        ] {
            assert!(!is_runner_output(other), "{other}");
        }
    }
}

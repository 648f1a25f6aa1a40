//! Where runners are built: one cargo target folder for the runners of every library,
//! so a second library compiles only its own crate and a small `main`.
//!
//! The folder is, first found: `FERROC_CACHE`; `CARGO_TARGET_DIR`; else the `target/`
//! of ferroc's checkout (the sources a runner is built from). `cargo install --locked
//! --path .` builds in that same `target/` (cargo's rule for `--path`), and a runner
//! takes the checkout's Cargo.lock and `[profile.*]`, so what the install compiled is
//! reused where the features agree (runner/Cargo.toml asks for the install's features of
//! the crates a runner shares with it). A user cache folder (`$XDG_CACHE_HOME/ferroc`,
//! `~/.cache/ferroc`) could not reuse it, and would outlive nothing useful: without the
//! checkout no runner can be built anyway. It is the fallback when the checkout's
//! `target/` cannot be written (a checkout owned by someone else).
//!
//! What ferroc puts there: `ferroc-runner/KEY/` (a runner's package and its build
//! record) and cargo's output for `ferroc-runner-KEY` in `PROFILE/`. A folder ferroc
//! made for itself (FERROC_CACHE or the user cache, found new or empty) is marked with
//! [`MARKER`]; only such a folder is emptied whole by `ferroc cache --clean`. In any other
//! (a checkout's `target/`, a `CARGO_TARGET_DIR` shared with other builds) the compiled
//! dependencies may be a developer's own, so only the runners' own files are removed.

use std::ffi::OsString;
use std::io::ErrorKind;
use std::path::{Path, PathBuf};

/// The file that marks a cache folder ferroc made for itself.
pub const MARKER: &str = "ferroc-cache.txt";

/// The folder of the runner packages inside the cache.
pub const PACKAGES: &str = "ferroc-runner";

/// The cargo profiles runners are built with (a debug ferroc builds debug runners).
pub const PROFILES: [&str; 2] = ["debug", "release"];

/// Why the cache is where it is.
#[derive(Clone, Debug, PartialEq)]
pub enum Origin {
    /// `FERROC_CACHE`.
    Named,
    /// `CARGO_TARGET_DIR` (shared with the user's other cargo builds).
    CargoTargetDir,
    /// The `target/` of ferroc's checkout (the default).
    Checkout,
    /// The user cache folder, because the checkout's `target/` is not writable.
    User,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Cache {
    pub dir: PathBuf,
    pub origin: Origin,
}

/// The cache of this ferroc (environment, checkout, user folder).
pub fn locate() -> Cache {
    let home = std::env::var_os("HOME").map(PathBuf::from);
    let user = user_cache(std::env::var_os("XDG_CACHE_HOME"), home);
    locate_from(
        std::env::var_os("FERROC_CACHE"),
        std::env::var_os("CARGO_TARGET_DIR"),
        &super::source_dir(),
        user,
        writable,
    )
}

/// `$XDG_CACHE_HOME/ferroc` (when absolute, as the XDG spec asks), else `~/.cache/ferroc`.
pub fn user_cache(xdg: Option<OsString>, home: Option<PathBuf>) -> Option<PathBuf> {
    let xdg = xdg.map(PathBuf::from).filter(|p| p.is_absolute());
    xdg.or_else(|| home.map(|h| h.join(".cache")))
        .map(|d| d.join("ferroc"))
}

pub fn locate_from(
    ferroc_cache: Option<OsString>,
    cargo_target: Option<OsString>,
    source: &Path,
    user: Option<PathBuf>,
    writable: impl Fn(&Path) -> bool,
) -> Cache {
    let absolute = |d: OsString| {
        let d = PathBuf::from(d);
        std::path::absolute(&d).unwrap_or(d)
    };
    if let Some(dir) = ferroc_cache.filter(|d| !d.is_empty()) {
        return Cache {
            dir: absolute(dir),
            origin: Origin::Named,
        };
    }
    if let Some(dir) = cargo_target.filter(|d| !d.is_empty()) {
        return Cache {
            dir: absolute(dir),
            origin: Origin::CargoTargetDir,
        };
    }
    let checkout = source.join("target");
    match user {
        Some(user) if !writable(&checkout) => Cache {
            dir: user,
            origin: Origin::User,
        },
        _ => Cache {
            dir: checkout,
            origin: Origin::Checkout,
        },
    }
}

/// Whether files can be made in `dir` (made first if needed): a probe file, removed.
fn writable(dir: &Path) -> bool {
    if std::fs::create_dir_all(dir).is_err() {
        return false;
    }
    let probe = dir.join(format!(".ferroc-probe-{}", std::process::id()));
    let made = std::fs::File::create(&probe).is_ok();
    let _ = std::fs::remove_file(&probe);
    made
}

impl Cache {
    /// Whether ferroc made this folder for itself (and may empty it whole).
    pub fn is_dedicated(&self) -> bool {
        self.dir.join(MARKER).is_file()
    }

    /// Why the cache is here, in a few words.
    pub fn origin_text(&self) -> &'static str {
        match self.origin {
            Origin::Named => "named by FERROC_CACHE",
            Origin::CargoTargetDir => "CARGO_TARGET_DIR, shared with your other cargo builds",
            Origin::Checkout => {
                "the default: the target folder of ferroc's checkout, where `cargo install --path` built ferroc"
            }
            Origin::User => {
                "the user cache folder: the target folder of ferroc's checkout is not writable"
            }
        }
    }

    /// Makes the folder (marked when ferroc makes it for itself) and checks that files
    /// can be written in it; else a message naming the folder and what to do.
    pub fn prepare(&self) -> Result<(), String> {
        let dedicated = matches!(self.origin, Origin::Named | Origin::User);
        let fresh = std::fs::read_dir(&self.dir).map_or(true, |mut d| d.next().is_none());
        let packages = self.dir.join(PACKAGES);
        let result = std::fs::create_dir_all(&packages).and_then(|()| {
            if dedicated && fresh {
                std::fs::write(self.dir.join(MARKER), MARKER_TEXT)?;
            }
            let probe = packages.join(format!(".probe-{}", std::process::id()));
            std::fs::write(&probe, b"ferroc")?;
            std::fs::remove_file(&probe)
        });
        result.map_err(|e| self.unusable(&e))
    }

    /// The message for an error writing into the cache: read-only, full, or other.
    pub fn unusable(&self, e: &std::io::Error) -> String {
        self.unusable_because(e.kind(), &e.to_string())
    }

    /// The message for a cache that cannot be written (`kind`), with the system's words.
    pub fn unusable_because(&self, kind: ErrorKind, detail: &str) -> String {
        let dir = self.dir.display();
        let (what, fix) = match kind {
            ErrorKind::PermissionDenied | ErrorKind::ReadOnlyFilesystem => {
                ("is not writable", "make it writable, or ")
            }
            ErrorKind::StorageFull | ErrorKind::QuotaExceeded => (
                "is full",
                "free space there (`ferroc cache --clean` removes the runners), or ",
            ),
            _ => ("cannot be used", ""),
        };
        format!(
            "error: the runner cache {dir} {what} ({detail})\n  \
             = the runners of libraries are built there ({})\n  \
             help: {fix}name another folder for them: FERROC_CACHE=DIR (`ferroc cache` shows where they are built)",
            self.origin_text()
        )
    }
}

const MARKER_TEXT: &str = "This folder is ferroc's build cache: the runners of `ferroc run` and \
`ferroc types` for libraries, and what cargo compiled for them.\n\
`ferroc cache` shows what it holds; `ferroc cache --clean` empties it.\n";

/// Whether cargo's error output says a disk is full.
pub fn says_full(line: &str) -> bool {
    line.contains("No space left on device") || line.contains("Disk quota exceeded")
}

impl Cache {
    /// After a failed build: the system's words if the cache has no room for a few
    /// megabytes. A full disk does not always say so: the linker writes through a
    /// memory map and dies of SIGBUS ("ld terminated with signal 7 [Bus error]").
    pub fn full_now(&self) -> Option<String> {
        let probe = self
            .dir
            .join(format!(".ferroc-room-{}", std::process::id()));
        let written = std::fs::write(&probe, vec![0u8; 4 << 20]);
        let _ = std::fs::remove_file(&probe);
        match written {
            Err(e) if matches!(e.kind(), ErrorKind::StorageFull | ErrorKind::QuotaExceeded) => {
                Some(e.to_string())
            }
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cache_is_named_or_the_checkout_s_target_or_the_user_s() {
        let source = Path::new("/src/ferroc");
        let user = Some(PathBuf::from("/home/u/.cache/ferroc"));
        let yes = |_: &Path| true;
        let no = |_: &Path| false;
        let at = |f: Option<&str>, c: Option<&str>, w: &dyn Fn(&Path) -> bool| {
            locate_from(
                f.map(Into::into),
                c.map(Into::into),
                source,
                user.clone(),
                w,
            )
        };
        assert_eq!(
            at(None, None, &yes),
            Cache {
                dir: "/src/ferroc/target".into(),
                origin: Origin::Checkout
            }
        );
        assert_eq!(
            at(None, None, &no),
            Cache {
                dir: "/home/u/.cache/ferroc".into(),
                origin: Origin::User
            }
        );
        assert_eq!(at(None, Some("/t"), &no).origin, Origin::CargoTargetDir);
        assert_eq!(at(Some("/c"), Some("/t"), &yes).dir, PathBuf::from("/c"));
        assert_eq!(at(Some("/c"), Some("/t"), &yes).origin, Origin::Named);
        // Empty counts as unset; a relative name is made absolute.
        assert_eq!(at(Some(""), Some(""), &yes).origin, Origin::Checkout);
        assert!(at(Some("rel"), None, &yes).dir.is_absolute());
    }

    #[test]
    fn the_user_cache_follows_xdg_when_absolute() {
        let home = Some(PathBuf::from("/home/u"));
        assert_eq!(
            user_cache(Some("/x".into()), home.clone()),
            Some("/x/ferroc".into())
        );
        assert_eq!(
            user_cache(Some("rel".into()), home.clone()),
            Some("/home/u/.cache/ferroc".into())
        );
        assert_eq!(user_cache(None, None), None);
    }

    #[test]
    fn only_a_folder_ferroc_makes_for_itself_is_marked() {
        let base = std::env::temp_dir().join(format!("ferroc-cache-mark-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&base);
        let cache = |dir: &str, origin| Cache {
            dir: base.join(dir),
            origin,
        };
        let named = cache("new", Origin::Named);
        named.prepare().unwrap();
        assert!(named.is_dedicated(), "made new for ferroc");
        assert!(named.dir.join(PACKAGES).is_dir());
        // A folder holding other things already is not ferroc's to empty.
        let busy = cache("busy", Origin::Named);
        std::fs::create_dir_all(&busy.dir).unwrap();
        std::fs::write(busy.dir.join("notes.txt"), "mine").unwrap();
        busy.prepare().unwrap();
        assert!(!busy.is_dedicated());
        // Nor is a checkout's target folder or CARGO_TARGET_DIR, even when new.
        for origin in [Origin::Checkout, Origin::CargoTargetDir] {
            let shared = cache("shared", origin);
            shared.prepare().unwrap();
            assert!(!shared.is_dedicated());
            std::fs::remove_dir_all(&shared.dir).unwrap();
        }
        std::fs::remove_dir_all(&base).unwrap();
    }
}

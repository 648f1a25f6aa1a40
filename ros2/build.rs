//! Lists the shipped interface definitions (`interfaces/<package>/{msg,srv}/*.{msg,srv}`)
//! so that the crate embeds every file in the folder and none is forgotten by hand.
use std::fmt::Write as _;
use std::path::Path;

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("interfaces");
    println!("cargo:rerun-if-changed={}", root.display());
    let mut files = Vec::new();
    // Only folders that exist: cargo copies these paths into the dep-info of every
    // program linking this crate, and a runner whose dep-info names a missing path is
    // never fresh (`ferroc run` would rebuild it on every run). A package's folder is
    // watched too, so a `msg/` or `srv/` added to it is seen.
    for package in read_dir(&root).into_iter().filter(|p| p.is_dir()) {
        println!("cargo:rerun-if-changed={}", package.display());
        for kind in ["msg", "srv"] {
            let dir = package.join(kind);
            if dir.is_dir() {
                println!("cargo:rerun-if-changed={}", dir.display());
                files.extend(
                    read_dir(&dir)
                        .into_iter()
                        .filter(|f| f.extension().is_some_and(|e| e == kind)),
                );
            }
        }
    }
    files.sort();
    let mut out = String::from("&[\n");
    for file in files {
        let rel = file.strip_prefix(&root).expect("under interfaces/");
        let _ = writeln!(
            out,
            "    ({:?}, include_str!({:?})),",
            rel.to_string_lossy().replace('\\', "/"),
            file.display().to_string()
        );
    }
    out.push(']');
    let dest = Path::new(&std::env::var("OUT_DIR").expect("OUT_DIR")).join("shipped.rs");
    std::fs::write(dest, out).expect("write shipped.rs");
}

fn read_dir(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .expect("interfaces/ readable")
        .map(|e| e.expect("entry").path())
        .collect();
    v.sort();
    v
}

//! The names of the workspace's crates, read from its manifests when ferroc is built:
//! `ferroc new library` refuses a name that collides with one of them (a library crate
//! named `ferroc_runtime` would shadow the runtime it depends on). Derived here so the
//! list cannot drift from the workspace.

use std::path::Path;

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    println!("cargo:rerun-if-changed=Cargo.toml");
    let manifest = std::fs::read_to_string(root.join("Cargo.toml")).expect("Cargo.toml");
    let mut names = Vec::new();
    for member in members(&manifest) {
        let path = root.join(&member).join("Cargo.toml");
        println!("cargo:rerun-if-changed={}", path.display());
        let text =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        names.push(package_name(&text).unwrap_or_else(|| panic!("{}: no name", path.display())));
    }
    names.sort();
    let out = Path::new(&std::env::var("OUT_DIR").expect("OUT_DIR")).join("workspace_crates.rs");
    let list = names
        .iter()
        .map(|n| format!("{n:?}"))
        .collect::<Vec<_>>()
        .join(", ");
    std::fs::write(out, format!("&[{list}]\n")).expect("OUT_DIR is writable");
}

/// The folders of `[workspace] members = [...]`.
fn members(manifest: &str) -> Vec<String> {
    let start = manifest.find("members = [").expect("[workspace] members");
    let rest = &manifest[start + "members = [".len()..];
    let list = &rest[..rest.find(']').expect("members end with ]")];
    list.split(',')
        .map(|m| m.trim().trim_matches('"').to_owned())
        .filter(|m| !m.is_empty())
        .collect()
}

/// The `name` of a manifest's `[package]`.
fn package_name(manifest: &str) -> Option<String> {
    let package = &manifest[manifest.find("[package]")?..];
    let line = package
        .lines()
        .find(|l| l.trim_start().starts_with("name"))?;
    let value = line.split_once('=')?.1.trim();
    Some(value.trim_matches('"').to_owned())
}

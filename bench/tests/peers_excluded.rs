//! `bench/peers` (Copper and dora-rs on our benchmarks, issue 32) is a cargo workspace
//! of its own and excluded from ferroc's, so `cargo build`/`cargo test` of ours never
//! builds Copper or dora. Reads manifests only (`cargo metadata --no-deps`): nothing
//! is resolved, fetched or built.

use std::path::Path;
use std::process::Command;

/// The manifest paths of the workspace members `cargo metadata` finds from `dir`.
fn member_manifests(dir: &Path) -> Vec<String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .args([
            "metadata",
            "--no-deps",
            "--offline",
            "--format-version",
            "1",
        ])
        .current_dir(dir)
        .output()
        .expect("cargo metadata runs");
    assert!(
        out.status.success(),
        "cargo metadata in {}: {}",
        dir.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    // Every package of `--no-deps` output is a member; its "manifest_path" names it.
    String::from_utf8_lossy(&out.stdout)
        .split("\"manifest_path\":\"")
        .skip(1)
        .filter_map(|rest| rest.split('"').next().map(str::to_string))
        .collect()
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap()
}

#[test]
fn ferrocs_workspace_has_no_member_under_bench_peers() {
    let members = member_manifests(root());
    assert!(
        members.iter().any(|m| m.ends_with("bench/Cargo.toml")),
        "ferroc-bench itself is a member: {members:?}"
    );
    let peers: Vec<_> = members
        .iter()
        .filter(|m| m.contains("bench/peers"))
        .collect();
    assert!(peers.is_empty(), "peers in ferroc's workspace: {peers:?}");
}

#[test]
fn the_peers_are_members_of_their_own_workspace() {
    // The same query from bench/peers finds Copper's and dora's crates there, so
    // the test above looks where they would be.
    let members = member_manifests(&root().join("bench/peers"));
    for crate_dir in ["copper-b2", "dora-b4"] {
        assert!(
            members
                .iter()
                .any(|m| m.contains(&format!("bench/peers/{crate_dir}/"))),
            "{crate_dir} not in bench/peers' workspace: {members:?}"
        );
    }
}

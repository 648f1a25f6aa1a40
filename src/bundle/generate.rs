//! Every file of the bundle, generated in memory: the workspace's and each part's Cargo
//! manifest, `main.rs`, systemd unit and launch script, the resolved model and
//! `manifest.json`.

use super::deps::{sources, STD_PACKAGE};
use super::files::Dependency;
use super::names::Names;
use super::{files, layout, out, resolved, rust, sha256, text, BundleArgs, Deps, TOOL_VERSION};
use ferroc_compiler::plan;
use ferroc_compiler::source::Span;

/// Every file of the bundle, in memory.
#[allow(clippy::too_many_arguments)]
pub(super) fn generate(
    args: &BundleArgs,
    result: &ferroc_compiler::CheckResult,
    plan: &plan::Plan,
    layout: &layout::Layout<'_>,
    deps: &[Dependency],
    cmdline: &[(String, String)],
    names: &Names<'_>,
    prefix: &str,
) -> Result<out::Files, String> {
    let mut files = out::Files::default();
    files.add(
        "Cargo.toml",
        files::workspace_toml(layout, deps, TOOL_VERSION),
    )?;
    files.add(
        "rustfmt.toml",
        "# The layout of the generated code (rustfmt's defaults).\nedition = \"2021\"\n",
    )?;
    if args.deps == Deps::Path {
        // The versions this checkout is built and tested with.
        if let Ok(lock) = std::fs::read(sources().join("Cargo.lock")) {
            files.add("Cargo.lock", lock)?;
        }
    }
    add_parts(&mut files, layout, deps, names, prefix, args.inspect)?;
    let mut hosts: Vec<&str> = layout.parts.iter().map(|p| p.host.as_str()).collect();
    hosts.sort();
    hosts.dedup();
    for host in hosts {
        files.add_executable(
            &format!("launch/{host}.sh"),
            files::launch_script(layout, host, TOOL_VERSION),
        )?;
    }
    add_resolved_model(&mut files, result, plan, layout, cmdline, names)?;
    let model_bytes = std::fs::read(&args.model)
        .map_err(|e| format!("cannot read {}: {e}", args.model.display()))?;
    let sources = result
        .sources
        .files()
        .map(|(_, f)| (names.file(f), sha256::hex(f.text.as_bytes())))
        .collect();
    let mut listed: Vec<String> = files.paths().map(str::to_string).collect();
    listed.push("manifest.json".into());
    listed.sort();
    let manifest = files::ManifestInput {
        tool_version: TOOL_VERSION,
        model_file: &names.model_file,
        model_sha256: sha256::hex(&model_bytes),
        sources,
        deps,
        files: listed,
    };
    files.add("manifest.json", files::manifest_json(layout, &manifest))?;
    Ok(files)
}

/// Each part's Cargo manifest, `main.rs` and systemd unit.
fn add_parts(
    files: &mut out::Files,
    layout: &layout::Layout<'_>,
    deps: &[Dependency],
    names: &Names<'_>,
    prefix: &str,
    inspect_all: bool,
) -> Result<(), String> {
    let at = |span: Span| names.at(span);
    let addresses: Vec<(String, String)> = (layout.parts.iter())
        .map(|p| (p.name.clone(), p.address.clone()))
        .collect();
    let cx = rust::Context {
        application: &layout.application,
        seed: layout.seed,
        parts: &addresses,
        periods: &layout.periods,
        model_file: &names.model_file,
        tool_version: TOOL_VERSION,
        inspect_all,
        at: &at,
    };
    for (i, part) in layout.parts.iter().enumerate() {
        let zenoh = deps.iter().find(|d| d.package == "ferroc-zenoh");
        let inspect = deps.iter().find(|d| d.package == "ferroc-inspect");
        let mut part_deps: Vec<&Dependency> = std::iter::once(&deps[0])
            .chain(inspect.filter(|_| part.is_inspected(inspect_all)))
            .chain(zenoh.filter(|_| part.uses_zenoh()))
            .chain(part.libraries.iter().filter_map(|l| {
                let package = &layout.libraries.get(l)?.package;
                deps.iter().find(|d| d.package == *package)
            }))
            .collect();
        if !part_deps.iter().any(|d| d.package == STD_PACKAGE) {
            part_deps.extend(deps.iter().find(|d| d.package == STD_PACKAGE));
        }
        let dir = format!("parts/{}", part.name);
        files.add(
            &format!("{dir}/Cargo.toml"),
            files::part_toml(layout, i, &part_deps, TOOL_VERSION),
        )?;
        files.add(&format!("{dir}/src/main.rs"), rust::main_rs(part, &cx))?;
        files.add(
            &format!("systemd/{}.service", part.package),
            files::systemd_unit(layout, i, prefix, TOOL_VERSION),
        )?;
    }
    Ok(())
}

/// The resolved model, with copies of the manifests it uses.
fn add_resolved_model(
    files: &mut out::Files,
    result: &ferroc_compiler::CheckResult,
    plan: &plan::Plan,
    layout: &layout::Layout<'_>,
    cmdline: &[(String, String)],
    names: &Names<'_>,
) -> Result<(), String> {
    let mut manifests = Vec::new();
    for lib in &result.libraries.libraries {
        if !text::is_name(&lib.name) {
            return Err(format!(
                "the library name `{}` cannot name a file",
                text::comment(&lib.name)
            ));
        }
        if lib.path.as_os_str().is_empty() {
            manifests.push((lib.name.clone(), None));
            continue;
        }
        let rel = format!("libraries/{}.lib.xml", lib.name);
        files.add(
            &format!("model/{rel}"),
            result.sources.get(lib.file).text.clone(),
        )?;
        manifests.push((lib.name.clone(), Some(rel)));
    }
    let app = result.app.as_ref().ok_or("no application")?;
    let resolved = resolved::document(
        app,
        &result.libraries,
        plan,
        &manifests,
        cmdline,
        &names.model_file,
        TOOL_VERSION,
    );
    files.add(&format!("model/{}.xml", layout.application), resolved)?;
    Ok(())
}

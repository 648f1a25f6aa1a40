//! `ferroc new`: start a library crate or a model that checks and runs as written.
//!
//! `ferroc new library NAME` writes a crate whose one module type has an input, an
//! output and a parameter, its manifest, a unit test and a model using it;
//! docs/writing-modules.md walks through exactly these files.

use crate::bundle::text::{is_name, toml_str, xml};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(clap::Args)]
pub struct NewArgs {
    #[command(subcommand)]
    what: What,
}

#[derive(clap::Subcommand)]
enum What {
    /// A library crate: Cargo.toml, NAME.lib.xml, src/lib.rs (one module type with a
    /// test) and demo.xml, a model using it
    #[command(
        long_about = "Write a library crate in DIR (default: ./NAME): Cargo.toml \
(depending on this ferroc's runtime by path), the manifest NAME.lib.xml, src/lib.rs with one \
module type (an input, an output, a parameter), its registration and a unit test, and demo.xml, \
a model using it. Then:\n\n  ferroc run NAME/demo.xml --cycles 5\n  \
ferroc types export --check --lib-path NAME\n  cargo test --manifest-path NAME/Cargo.toml\n\n\
docs/writing-modules.md explains every file."
    )]
    Library {
        /// The library's name: lowercase letters, digits and `_` (the package name is
        /// the same with `-`)
        name: String,
        /// Folder to create (must not exist or be empty)
        #[arg(long, value_name = "DIR")]
        dir: Option<PathBuf>,
    },
    /// A model: one part, one thread container, one instance of each module type of
    /// the library given (or a standard-library example)
    Model {
        /// The model file to write (must not exist)
        file: PathBuf,
        /// A library manifest whose module types the model instantiates
        #[arg(long, value_name = "MANIFEST")]
        library: Option<PathBuf>,
    },
}

pub fn run(args: NewArgs) -> ExitCode {
    let result = match args.what {
        What::Library { name, dir } => library(&name, dir),
        What::Model { file, library } => model(&file, library.as_deref()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

fn library(name: &str, dir: Option<PathBuf>) -> Result<(), String> {
    let valid = is_name(name)
        && name.starts_with(|c: char| c.is_ascii_lowercase())
        && name
            .chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_');
    if !valid || name == "ferroc_std" {
        return Err(format!(
            "`{}` cannot name a library\n  help: use lowercase letters, digits and `_`, starting with a letter, e.g. `my_robot`",
            crate::bundle::text::comment(name)
        ));
    }
    let dir = dir.unwrap_or_else(|| PathBuf::from(name));
    empty_or_new(&dir)?;
    let package = name.replace('_', "-");
    let runtime = crate::runner::program::source_dir().join("runtime");
    let files = [
        ("Cargo.toml", cargo_toml(&package, name, &runtime)),
        (&format!("{name}.lib.xml") as &str, manifest(name, &package)),
        ("src/lib.rs", lib_rs(name)),
        ("demo.xml", demo_model(name)),
    ];
    for (file, text) in &files {
        write_new(&dir.join(file), text)?;
    }
    let shown = dir.display();
    eprintln!(
        "wrote the library `{name}` in {shown}: Cargo.toml, {name}.lib.xml, src/lib.rs, demo.xml\n\
         next:\n  ferroc run {shown}/demo.xml --cycles 5\n  \
         ferroc types export --check --lib-path {shown}\n  \
         cargo test --manifest-path {shown}/Cargo.toml"
    );
    Ok(())
}

fn empty_or_new(dir: &Path) -> Result<(), String> {
    match std::fs::read_dir(dir).map(|mut entries| entries.next().is_some()) {
        Ok(true) => Err(format!(
            "{} exists and is not empty\n  help: choose another folder with --dir",
            dir.display()
        )),
        Ok(_) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(format!("cannot use {}: {e}", dir.display())),
    }
}

/// Writes a file that must not exist yet (never overwrites).
fn write_new(path: &Path, text: &str) -> Result<(), String> {
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent)
            .map_err(|e| format!("cannot create {}: {e}", parent.display()))?;
    }
    use std::io::Write;
    let mut file = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(path)
        .map_err(|e| format!("cannot create {}: {e}", path.display()))?;
    file.write_all(text.as_bytes())
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

fn cargo_toml(package: &str, name: &str, runtime: &Path) -> String {
    format!(
        "[package]\nname = \"{package}\"\nversion = \"0.1.0\"\nedition = \"2021\"\npublish = false\n\n\
         [lib]\nname = \"{name}\"\n\n\
         [dependencies]\n\
         # The ferroc runtime: ports, parameters, the module traits. `ferroc run` links this\n\
         # crate into a runner together with the runtime, so both must be the same one.\n\
         ferroc-runtime = {{ path = {} }}\n\n\
         # A crate of its own; delete this line to make it a member of an enclosing workspace.\n\
         [workspace]\n",
        toml_str(&runtime.to_string_lossy())
    )
}

fn manifest(name: &str, package: &str) -> String {
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<!--
  The library `{name}`: what its module types look like to a model. ferroc checks models
  against this file; `ferroc types export --check` checks it against the Rust code of
  the crate `{package}` (rust-crate=, in this folder).
-->
<library name="{name}" version="0.1.0" rust-crate="{package}"
         doc="Started with ferroc new library">

  <module-type name="Accumulator" rust="{name}::Accumulator" budget="20us"
               doc="Adds gain times step to its total every cycle">
    <in name="step" type="f64" doc="added every cycle, times gain"/>
    <out name="total" type="f64" doc="the sum so far"/>
    <param name="gain" type="f64" default="1" min="0" max="100" doc="factor applied to every step"/>
  </module-type>
</library>
"#
    )
}

fn lib_rs(name: &str) -> String {
    format!(
        r#"//! The library `{name}`: the Rust code of the module types in `{name}.lib.xml`.

use ferroc_runtime::builder::Registry;
use ferroc_runtime::module::{{In, Module, ModuleType, Out, Parameter, Setup}};

/// Adds `gain` times its input `step` to a running total and publishes it.
pub struct Accumulator {{
    step: In<f64>,
    total_out: Out<f64>,
    gain: Parameter<f64>,
    total: f64,
}}

impl ModuleType for Accumulator {{
    /// The model's name of the type: library, dot, module type.
    const NAME: &'static str = "{name}.Accumulator";
    const DOC: &'static str = "Adds gain times step to its total every cycle";

    /// Declares the ports and parameters (`ferroc types export` reads them from here).
    fn create(m: &mut Setup<'_>) -> Self {{
        Accumulator {{
            step: m.input("step").doc("added every cycle, times gain").build(),
            total_out: m.output("total").doc("the sum so far").build(),
            gain: m
                .param("gain")
                .default(1.0)
                .range(0.0, 100.0)
                .doc("factor applied to every step")
                .build(),
            total: 0.0,
        }}
    }}
}}

impl Module for Accumulator {{
    /// Runs once per cycle of the thread container the model puts it in.
    fn update(&mut self) {{
        self.total = accumulate(self.total, self.step.get(), self.gain.get());
        self.total_out.publish(self.total);
        println!("[{name}] total = {{:.2}}", self.total);
    }}
}}

/// The arithmetic, kept apart from the ports so it is easy to test.
pub fn accumulate(total: f64, step: f64, gain: f64) -> f64 {{
    total + gain * step
}}

/// Registers the library's module types; the runner `ferroc run` builds calls this.
pub fn register(registry: &mut Registry) {{
    registry.register::<Accumulator>();
}}

#[cfg(test)]
mod tests {{
    use super::*;

    #[test]
    fn each_step_adds_gain_times_step() {{
        let total = accumulate(0.0, 0.5, 2.0);
        assert_eq!(total, 1.0);
        assert_eq!(accumulate(total, 0.25, 4.0), 2.0);
    }}

    #[test]
    fn the_registered_interface_has_the_ports_and_parameter_of_the_manifest() {{
        let mut registry = Registry::new();
        register(&mut registry);
        let interface = registry.interface("{name}.Accumulator").expect("registered");
        assert!(interface.port("step").is_some());
        assert!(interface.port("total").is_some());
        assert_eq!(interface.params.len(), 1);
        assert_eq!(interface.params[0].name, "gain");
    }}
}}
"#
    )
}

fn demo_model(name: &str) -> String {
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<!--
  A model using the library `{name}`: a constant feeds an accumulator ten times a second.
    ferroc check demo.xml
    ferroc run demo.xml --cycles 5
-->
<application name="{name}_demo" version="1">
  <use library="ferroc_std"/>
  <use library="{name}" manifest="{name}.lib.xml"/>

  <part name="main" host="localhost">
    <thread name="loop" period="100ms">
      <module name="source" type="ferroc_std.Constant">
        <param name="value">0.5</param>
      </module>
      <module name="sum" type="{name}.Accumulator">
        <param name="gain">2</param>
      </module>
      <connect from="source/value" to="sum/step"/>
    </thread>
  </part>
</application>
"#
    )
}

/// `ferroc new model FILE`: one part and thread container; with `--library`, one
/// instance of each of its module types, else a standard-library example.
fn model(file: &Path, library: Option<&Path>) -> Result<(), String> {
    let stem = file
        .file_stem()
        .map(|s| s.to_string_lossy().replace(['-', '.', ' '], "_"))
        .unwrap_or_default();
    let app = if is_name(&stem) {
        stem
    } else {
        "app".to_string()
    };
    let mut uses = String::from("  <use library=\"ferroc_std\"/>\n");
    let mut modules = String::new();
    match library {
        Some(manifest) => {
            let (lib, types) = module_types_of(manifest)?;
            let rel = relative_to(file, manifest);
            uses.push_str(&format!(
                "  <use library=\"{}\" manifest=\"{}\"/>\n",
                xml(&lib),
                xml(&rel)
            ));
            for t in &types {
                modules.push_str(&format!(
                    "      <module name=\"{}\" type=\"{}.{}\"/>\n",
                    xml(&t.to_lowercase()),
                    xml(&lib),
                    xml(t)
                ));
            }
            modules.push_str("      <!-- <connect from=\"a/out\" to=\"b/in\"/> -->\n");
        }
        None => modules.push_str(
            "      <module name=\"source\" type=\"ferroc_std.Constant\">\n        <param name=\"value\">1.5</param>\n      </module>\n      <module name=\"double\" type=\"ferroc_std.Scale\">\n        <param name=\"factor\">2</param>\n      </module>\n      <connect from=\"source/value\" to=\"double/input\"/>\n",
        ),
    }
    let text = format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<application name=\"{app}\" version=\"1\">\n{uses}\n  <part name=\"main\" host=\"localhost\">\n    <thread name=\"loop\" period=\"100ms\">\n{modules}    </thread>\n  </part>\n</application>\n"
    );
    write_new(file, &text)?;
    eprintln!(
        "wrote {}\nnext:\n  ferroc check {}\n  ferroc run {} --cycles 5",
        file.display(),
        file.display(),
        file.display()
    );
    Ok(())
}

/// The library name and module type names of a manifest `NAME.lib.xml`.
fn module_types_of(manifest: &Path) -> Result<(String, Vec<String>), String> {
    let file = manifest.file_name().unwrap_or_default().to_string_lossy();
    let Some(name) = file.strip_suffix(".lib.xml") else {
        return Err(format!(
            "{}: a library manifest is named NAME.lib.xml",
            manifest.display()
        ));
    };
    let dir = manifest.parent().unwrap_or(Path::new(".")).to_path_buf();
    let options = ferroc_host::loader_options(&[dir], false);
    let loaded = ferroc_compiler::load_manifests(&[name.to_string()], &options);
    let Some(&id) = loaded.libraries.by_name.get(name) else {
        let why = loaded
            .diagnostics
            .first()
            .map(|d| d.message.clone())
            .unwrap_or_else(|| "cannot be read".into());
        return Err(format!("{}: {why}", manifest.display()));
    };
    let lib = loaded.libraries.get(id);
    Ok((
        lib.name.clone(),
        lib.module_types.iter().map(|t| t.name.clone()).collect(),
    ))
}

/// `to` as the model at `from` refers to it (relative when both are relative).
fn relative_to(from: &Path, to: &Path) -> String {
    let base = from.parent().unwrap_or(Path::new(""));
    let (Ok(base), Ok(to_abs)) = (std::path::absolute(base), std::path::absolute(to)) else {
        return to.to_string_lossy().into_owned();
    };
    let b: Vec<_> = base.components().collect();
    let t: Vec<_> = to_abs.components().collect();
    let common = b.iter().zip(&t).take_while(|(x, y)| x == y).count();
    if common <= 1 {
        return to_abs.to_string_lossy().into_owned();
    }
    let mut parts: Vec<String> = vec!["..".into(); b.len() - common];
    parts.extend(
        t[common..]
            .iter()
            .map(|c| c.as_os_str().to_string_lossy().into_owned()),
    );
    parts.join("/")
}

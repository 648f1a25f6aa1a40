//! `ferroc inspect`: look into a program running with `--inspect` (docs/inspect.md):
//! list its element tree and figures, read a port or parameter, change a parameter
//! (with the program's token), watch a port for a while, or serve it all over the
//! Foxglove WebSocket protocol (`--foxglove`, inspect/src/foxglove/).

use ferroc_compiler::diagnostic::{did_you_mean, escape_controls};
use ferroc_inspect::client::{part_of, Answer, Client};
use ferroc_inspect::request::{key, What};
use ferroc_inspect::web;
use ferroc_runtime::inspect::ros2;
use ferroc_runtime::inspect::view::*;
use std::process::ExitCode;
use std::time::{Duration, Instant};

#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("action").required(true).args(["list", "get", "set", "watch", "serve", "edit", "save", "foxglove"])))]
pub struct InspectArgs {
    /// The program's inspection address (its `--inspect ADDR`; repeatable)
    #[arg(long, value_name = "HOST:PORT", default_value = "127.0.0.1:47900")]
    connect: Vec<String>,
    /// The application's name (default: any)
    #[arg(long, value_name = "APP", default_value = "*")]
    app: String,
    /// List every part: modules (type, kind, source, ports, parameters), thread
    /// containers' figures, links, iB2C activities
    #[arg(long)]
    list: bool,
    /// Print the latest value of a port or the value of a parameter: MODULE/PATH/NAME
    #[arg(long, value_name = "PATH")]
    get: Option<String>,
    /// Change a parameter: MODULE/PATH/NAME=VALUE (with a unit if it has one: 0.3 m/s);
    /// needs --token
    #[arg(long, value_name = "PATH=VALUE", requires = "token")]
    set: Option<String>,
    /// Change the running application's structure: a JSON file of edit operations
    /// (`-`: standard input), checked by the compiler before it is applied; needs
    /// --token (docs/inspect.md, "Structural edits")
    #[arg(long, value_name = "OPS.json", requires = "token")]
    edit: Option<std::path::PathBuf>,
    /// Write the model the program runs now (edits and parameter changes included)
    /// to FILE (`-`: standard output)
    #[arg(long, value_name = "FILE")]
    save: Option<std::path::PathBuf>,
    /// The token the program printed at start (for --set and --edit, and for
    /// --foxglove to change parameters)
    #[arg(long, value_name = "TOKEN", env = "FERROC_INSPECT_TOKEN")]
    token: Option<String>,
    /// Print a port's value every --every until --for or --count ends it (or Ctrl-C)
    #[arg(long, value_name = "PATH")]
    watch: Option<String>,
    /// Serve the application's ports, figures and parameters over the Foxglove
    /// WebSocket protocol on HOST:PORT (default 127.0.0.1:8765), until --for ends it
    #[arg(long, value_name = "HOST:PORT", num_args = 0..=1, default_missing_value = ferroc_inspect::foxglove::DEFAULT_ADDRESS)]
    foxglove: Option<String>,
    /// With --foxglove: serve on an address other computers can reach
    #[arg(long, requires = "foxglove")]
    foxglove_public: bool,
    /// With --foxglove: let web pages of this origin connect (`https://host:port`;
    /// repeatable). The Foxglove app's https://app.foxglove.dev always may; clients
    /// that are not browsers send no origin and always may
    #[arg(long, value_name = "ORIGIN", requires = "foxglove")]
    foxglove_origin: Vec<String>,
    /// With --watch or --foxglove: stop after this long (`5s`, `500ms`)
    #[arg(long = "for", value_name = "DURATION", value_parser = parse_duration)]
    duration: Option<Duration>,
    /// With --watch: stop after this many values
    #[arg(long, value_name = "N")]
    count: Option<u64>,
    /// With --watch or --foxglove: how often to ask (--foxglove: for each channel a
    /// client subscribed to)
    #[arg(long, value_name = "DURATION", default_value = "100ms", value_parser = parse_duration)]
    every: Duration,
    /// Serve a web page showing the application live (graph, values, plots, load,
    /// links, activities, parameter changes) on HOST:PORT until Ctrl-C
    #[arg(long, value_name = "HOST:PORT", num_args = 0..=1, default_missing_value = "127.0.0.1:8790")]
    serve: Option<String>,
    /// With --serve: allow an address other computers can reach (prints a warning)
    #[arg(long, requires = "serve")]
    serve_public: bool,
    /// Print the answers as JSON (one object, or one line per value with --watch)
    #[arg(long)]
    json: bool,
}

fn parse_duration(text: &str) -> Result<Duration, String> {
    let seconds = ferroc_compiler::values::parse_duration(text)
        .map_err(|_| format!("`{text}` is not a duration; write e.g. 5s or 500ms"))?;
    if !(0.0..=1e9).contains(&seconds) {
        return Err(format!("`{text}` is out of range"));
    }
    Ok(Duration::from_secs_f64(seconds))
}

pub fn run(args: InspectArgs) -> ExitCode {
    if let Some(listen) = &args.serve {
        return serve(&args, listen);
    }
    if let Some(address) = &args.foxglove {
        return foxglove(&args, address);
    }
    let client = match Client::connect(&args.connect) {
        Ok(c) => c,
        Err(e) => return fail(2, &e),
    };
    let result: Result<(), Failure> = if args.list {
        list(&client, &args)
    } else if let Some(path) = &args.get {
        get(&client, &args, path)
    } else if let Some(assignment) = &args.set {
        set(&client, &args, assignment)
    } else if let Some(path) = &args.watch {
        watch(&client, &args, path)
    } else if let Some(ops) = &args.edit {
        let token = args.token.as_deref().unwrap_or_default();
        crate::inspect_edit::edit(&client, &args.app, ops, token, args.json)
    } else if let Some(file) = &args.save {
        crate::inspect_edit::save(&client, &args.app, file)
    } else {
        Ok(())
    };
    match result {
        Ok(()) | Err(Failure::ReaderGone) => ExitCode::SUCCESS,
        Err(Failure::Refused(e)) => {
            eprintln!("error: {}", escape_controls(&e));
            if let Some(near) = nearest_path(&client, &args) {
                eprintln!("  help: did you mean `{}`?", escape_controls(&near));
            }
            ExitCode::from(1)
        }
        Err(Failure::Output(code)) => code,
    }
}

/// For `--get`, `--set` and `--watch` of a path the programs do not have: the nearest
/// path they do have (ports for --watch, parameters for --set, both for --get), by the
/// compiler's "did you mean" (`ferroc check` suggests names the same way).
fn nearest_path(client: &Client, args: &InspectArgs) -> Option<String> {
    let (path, ports, params) = if let Some(p) = &args.get {
        (p.as_str(), true, true)
    } else if let Some(p) = &args.watch {
        (p.as_str(), true, false)
    } else {
        let assignment = args.set.as_deref()?;
        (assignment.split_once('=')?.0.trim(), false, true)
    };
    let trees = client.ask_once(&key(&args.app, "*", &What::Tree), None, TREE_TIMEOUT);
    let mut known = Vec::new();
    for tree in trees.ok()?.iter().filter_map(|a| a.parse::<Tree>().ok()) {
        for m in tree.modules {
            let names = (m.ports.iter().filter(|_| ports).map(|p| &p.name))
                .chain(m.params.iter().filter(|_| params).map(|p| &p.name));
            known.extend(names.map(|n| format!("{}/{n}", m.path)));
        }
    }
    if known.iter().any(|k| k == path) {
        return None; // it exists: the refusal was for another reason
    }
    did_you_mean(path, known.iter().map(String::as_str)).map(str::to_owned)
}

/// How long [`nearest_path`] waits for the element trees (the programs answered the
/// failed request already, or did not at all).
const TREE_TIMEOUT: Duration = Duration::from_secs(2);

/// Why an action of `ferroc inspect` ended early.
pub(crate) enum Failure {
    /// The program refused, or nobody answered: exit code 1 with the reason.
    Refused(String),
    /// Standard output cannot be written (a full disk): said already, exit code 2.
    Output(ExitCode),
    /// The reader of standard output is gone (`| head -1`): stop quietly, as the other
    /// commands do.
    ReaderGone,
}

impl From<String> for Failure {
    fn from(e: String) -> Failure {
        Failure::Refused(e)
    }
}

/// Writes `text` to standard output as every command does (crate::output): a closed
/// pipe ends the action quietly, another failure is exit code 2.
pub(crate) fn emit(text: &str) -> Result<(), Failure> {
    match crate::output::write(text.as_bytes()) {
        Ok(crate::output::Written::Read) => Ok(()),
        Ok(crate::output::Written::ReaderGone) => Err(Failure::ReaderGone),
        Err(code) => Err(Failure::Output(code)),
    }
}

/// [`emit`] of one line.
fn line(text: impl std::fmt::Display) -> Result<(), Failure> {
    emit(&format!("{text}\n"))
}

/// `--serve`: the web page (ferroc_inspect::web) until Ctrl-C; it connects to the
/// program itself, and again whenever the program was unreachable.
fn serve(args: &InspectArgs, listen: &str) -> ExitCode {
    let limits = match ferroc_inspect::limits::Limits::from_env() {
        Ok(l) => l,
        Err(e) => return fail(2, &e),
    };
    let options = web::Options {
        listen: listen.to_owned(),
        public: args.serve_public,
        connect: args.connect.clone(),
        app: args.app.clone(),
        limits,
    };
    let server = match web::start(&options) {
        Ok(s) => s,
        Err(web::StartError(e)) => return fail(2, &e),
    };
    let address = server.address();
    if !address.ip().is_loopback() {
        eprintln!(
            "warning: the inspection page is served on {address}, not only on this computer: anyone who reaches it can read every value (changes still need the token)"
        );
    }
    eprintln!(
        "inspect: the page is on http://{address}/ (asking {}); Ctrl-C stops",
        args.connect.join(", ")
    );
    match server.wait() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => fail(2, &e),
    }
}

fn foxglove(args: &InspectArgs, address: &str) -> ExitCode {
    use ferroc_inspect::foxglove::{bind_address, run, Options};
    if let Err(e) = bind_address(address, args.foxglove_public) {
        return fail(2, &e);
    }
    let limits = match ferroc_inspect::limits::Limits::from_env() {
        Ok(l) => l,
        Err(e) => return fail(2, &e),
    };
    let options = Options {
        address: address.to_owned(),
        public: args.foxglove_public,
        app: args.app.clone(),
        token: args.token.clone(),
        origins: args.foxglove_origin.clone(),
        limits,
        every: args.every,
        duration: args.duration,
    };
    match Client::connect(&args.connect).and_then(|client| run(client, &options)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => fail(2, &e),
    }
}

fn fail(code: u8, message: &str) -> ExitCode {
    eprintln!("error: {}", escape_controls(message));
    ExitCode::from(code)
}

fn list(client: &Client, args: &InspectArgs) -> Result<(), Failure> {
    let trees = client.ask(&key(&args.app, "*", &What::Tree), None)?;
    if trees.is_empty() {
        return Err(Failure::Refused(format!(
            "no program answered on {}: is it running with --inspect, and is --app right?",
            args.connect.join(", ")
        )));
    }
    let mut all = serde_json::Map::new();
    for answer in &trees {
        let (app, part) = answer.app_part();
        let tree: Tree = answer.parse()?;
        let containers: Vec<ContainerView> = client.one(app, part, &What::Containers)?;
        let links: Vec<LinkView> = client.one(app, part, &What::Links)?;
        let activities: Vec<ActivityView> = client.one(app, part, &What::Activities)?;
        // A program built before `transport` was asked answers it with an error: none.
        let transport: TransportView =
            (client.one(app, part, &What::Transport)).unwrap_or_default();
        if args.json {
            all.insert(
                format!("{app}/{part}"),
                serde_json::json!({
                    "tree": tree, "containers": containers, "links": links,
                    "activities": activities, "transport": transport
                }),
            );
            continue;
        }
        let figures = (&containers[..], &links[..], &activities[..], &transport);
        line(escape_controls(show_part(app, part, &tree, figures)))?;
    }
    if args.json {
        line(serde_json::Value::Object(all))?;
    }
    Ok(())
}

/// A part's figures besides its tree: containers, links into it, activities, and how
/// its links to other parts travel.
type Figures<'a> = (
    &'a [ContainerView],
    &'a [LinkView],
    &'a [ActivityView],
    &'a TransportView,
);

fn show_part(app: &str, part: &str, tree: &Tree, figures: Figures<'_>) -> String {
    let (containers, links, activities, transport) = figures;
    use std::fmt::Write;
    let mut s = format!("application {app}, part {part}\n");
    for c in containers {
        let _ = writeln!(
            s,
            "  container {}: {} cycles, {} overruns, load {:.1} %, mean cycle {:.0} µs",
            c.path,
            c.cycles,
            c.overruns,
            c.load * 100.0,
            c.mean_cycle_us
        );
    }
    for m in &tree.modules {
        let _ = writeln!(
            s,
            "  module {} : {} ({}){}{}",
            m.path,
            m.r#type,
            m.kind,
            m.source
                .as_ref()
                .map(|x| format!(" at {x}"))
                .unwrap_or_default(),
            m.container
                .as_ref()
                .map(|x| format!(", in {x}"))
                .unwrap_or_default(),
        );
        for p in &m.ports {
            let unit = p
                .unit
                .as_ref()
                .map(|u| format!(" [{u}]"))
                .unwrap_or_default();
            let from = if p.from.is_empty() {
                String::new()
            } else {
                format!(" ← {}", p.from.join(", "))
            };
            let _ = writeln!(s, "    {:<3} {}: {}{unit}{from}", p.dir, p.name, p.r#type);
            for end in m.ros2.iter().filter(|e| is_topic(e) && e.port == p.name) {
                let _ = writeln!(s, "        {}", ros2::describe(end));
            }
        }
        for end in m.ros2.iter().filter(|e| !is_topic(e)) {
            let _ = writeln!(s, "    {} {}: {}", end.role, end.port, ros2::describe(end));
        }
        for p in &m.params {
            let _ = writeln!(s, "    param {}", show_param(p));
        }
    }
    for l in links {
        let age = l
            .age_ms
            .map(|a| format!(", {a:.0} ms ago"))
            .unwrap_or_default();
        let _ = writeln!(s, "  link into {}: {}{age}", l.input, l.state);
    }
    show_transport(&mut s, transport);
    for a in activities {
        let n = |x: Option<f64>| x.map_or("-".into(), |x| format!("{x:.3}"));
        let _ = writeln!(
            s,
            "  behaviour {}: activity {}, target rating {}",
            a.module,
            n(a.activity),
            n(a.target_rating)
        );
    }
    s.trim_end().to_owned()
}

/// How the links `transport` names travel, a line each, and the pool's use:
/// `link out of robot/cam/image to station: shared memory (120 in shared memory, 0 over
/// the network, 0 dropped)`, `shared memory pool: 6.0 MiB of 64.0 MiB in use, for
/// values of 4.0 KiB and more`, and once a reader that held buffers is gone (killed),
/// `; of readers that are gone: 3 buffers back, 0 not yet`.
fn show_transport(s: &mut String, transport: &TransportView) {
    use std::fmt::Write;
    for l in &transport.links {
        let _ = writeln!(
            s,
            "  link out of {} to {}: {} ({} in shared memory, {} over the network, {} dropped)",
            l.output, l.to_part, l.by, l.shared_memory, l.network, l.dropped
        );
    }
    if let Some(p) = &transport.pool {
        let gone = match (p.reclaimed, p.gone_held) {
            (0, 0) => String::new(),
            (back, held) => format!(
                "; of readers that are gone: {back} buffer{} back, {held} not yet",
                if back == 1 { "" } else { "s" }
            ),
        };
        let _ = writeln!(
            s,
            "  shared memory pool: {} of {} in use, for values of {} and more{gone}",
            size(p.used),
            size(p.size),
            size(p.threshold)
        );
    }
}

/// A number of bytes as people read it: `512 bytes`, `4.0 KiB`, `64.0 MiB`.
fn size(bytes: u64) -> String {
    const KIB: u64 = 1024;
    let x = bytes as f64;
    match bytes {
        b if b < KIB => format!("{b} bytes"),
        b if b < KIB * KIB => format!("{:.1} KiB", x / 1024.0),
        _ => format!("{:.1} MiB", x / (1024.0 * 1024.0)),
    }
}

/// A port published or subscribed as a ROS 2 topic (else a service or client).
fn is_topic(end: &Ros2View) -> bool {
    matches!(end.role.as_str(), "publish" | "subscribe")
}

fn show_param(p: &ParamView) -> String {
    let unit = p.unit.as_ref().map(|u| format!(" {u}")).unwrap_or_default();
    let mut limits = vec![p.r#type.clone()];
    if p.min.is_some() || p.max.is_some() {
        let n = |x: Option<f64>| x.map(|x| x.to_string()).unwrap_or_default();
        limits.push(format!("{}..={}", n(p.min), n(p.max)));
    }
    if !p.choices.is_empty() {
        limits.push(format!("one of {}", p.choices.join(", ")));
    }
    format!("{} = {}{unit} ({})", p.name, p.value, limits.join(", "))
}

fn get(client: &Client, args: &InspectArgs, path: &str) -> Result<(), Failure> {
    let part = part_of(path);
    let value = client.ask(&key(&args.app, part, &What::Value(path.into())), None)?;
    match value.first().map(|a| a.parse::<PortValue>()) {
        Some(Ok(v)) => print_value(&v, args.json, None),
        Some(Err(port_error)) => {
            // Not a port: perhaps a parameter.
            let param = client.ask(&key(&args.app, part, &What::Param(path.into())), None)?;
            match param.first().map(Answer::parse::<ParamView>) {
                Some(Ok(p)) => print_param(&p, args.json),
                Some(Err(param_error)) if param_error.contains("has no parameter") => {
                    Err(format!("{port_error}; {param_error}").into())
                }
                Some(Err(e)) => Err(e.into()),
                None => Err(port_error.into()),
            }
        }
        None => Err(nobody(args, part, path).into()),
    }
}

fn nobody(args: &InspectArgs, part: &str, path: &str) -> String {
    format!(
        "no program on {} answered for `{path}` (part `{part}`): check the path with --list",
        args.connect.join(", ")
    )
}

fn print_value(v: &PortValue, json: bool, at: Option<f64>) -> Result<(), Failure> {
    if json {
        let mut value = serde_json::to_value(v).unwrap_or_default();
        if let (Some(t), Some(o)) = (at, value.as_object_mut()) {
            o.insert("t".into(), serde_json::json!(t));
        }
        return line(value);
    }
    let unit = v.unit.as_ref().map(|u| format!(" {u}")).unwrap_or_default();
    let note = if v.published {
        ""
    } else {
        " (nothing published yet)"
    };
    let text = match at {
        Some(t) => format!("{t:8.3} s  {}{unit}{note}", v.value),
        None => format!("{} = {}{unit}{note}", v.port, v.value),
    };
    line(escape_controls(text))
}

fn print_param(p: &ParamView, json: bool) -> Result<(), Failure> {
    if json {
        line(serde_json::to_value(p).unwrap_or_default())
    } else {
        line(format!(
            "{}/{}",
            escape_controls(&p.module),
            escape_controls(show_param(p))
        ))
    }
}

fn set(client: &Client, args: &InspectArgs, assignment: &str) -> Result<(), Failure> {
    let Some((path, value)) = assignment.split_once('=') else {
        return Err(Failure::Refused(format!(
            "--set {assignment}: write MODULE/PATH/NAME=VALUE, e.g. --set robot/avoid/min_activity=0.4"
        )));
    };
    let token = args.token.as_deref().unwrap_or_default();
    let p: ParamView = client.set(&args.app, path.trim(), value.trim(), token)?;
    print_param(&p, args.json)
}

fn watch(client: &Client, args: &InspectArgs, path: &str) -> Result<(), Failure> {
    let what = What::Value(path.into());
    let key = key(&args.app, part_of(path), &what);
    let start = Instant::now();
    let mut printed = 0u64;
    loop {
        if args.count.is_some_and(|n| printed >= n)
            || args.duration.is_some_and(|d| start.elapsed() >= d)
        {
            return Ok(());
        }
        let asked = Instant::now();
        let answers = client.ask(&key, None)?;
        let v: PortValue = match answers.first() {
            Some(a) => a.parse()?,
            None => return Err(nobody(args, part_of(path), path).into()),
        };
        // A reader that went away ends the watch (quietly, exit code 0).
        print_value(&v, args.json, Some(start.elapsed().as_secs_f64()))?;
        printed += 1;
        let next = asked + args.every;
        let now = Instant::now();
        if next > now {
            let left = args.duration.map_or(next - now, |d| {
                (next - now).min(d.saturating_sub(start.elapsed()))
            });
            std::thread::sleep(left);
        }
    }
}

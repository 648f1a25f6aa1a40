//! The small command line of a generated part program (`--cycles N`, `--for 10s`,
//! `--quiet`, `--lockstep`, the network and recording options, `--inspect`, `--help`),
//! parsed without a dependency so a bundle's program stays lean.

use super::Options;
use std::io::IsTerminal;
use std::process::ExitCode;
use std::time::Duration;

/// The command line of a generated program.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Args {
    /// `--cycles N`: stop after N cycles of the application (of its fastest periodic
    /// thread containers, see [`crate::builder::cycles_of`]).
    pub cycles: Option<u64>,
    /// `--for DURATION`: stop after this long.
    pub duration: Option<Duration>,
    /// `--quiet` / `-q`: no live status line.
    pub quiet: bool,
    /// `--lockstep`: simulated time, the same output on every run.
    pub lockstep: bool,
    /// `--local`: every part on this computer (127.0.0.1, ports unchanged).
    pub local: bool,
    /// `--peer PART=HOST:PORT`: where a part listens (repeatable).
    pub peers: Vec<(String, String)>,
    /// `--listen ADDR`: where this part listens (default: its own port, all interfaces).
    pub listen: Option<String>,
    /// `--zenoh-config FILE`: the network's own configuration (Zenoh's JSON5), for
    /// routers, scouting or access control, merged with ferroc's defaults.
    pub zenoh_config: Option<std::path::PathBuf>,
    /// `--record FILE`: record the outputs of this program's modules that feed a
    /// connection into an MCAP file (what `ferroc run --record` does; the recorders
    /// are `ferroc_std`'s, which a generated program adds when it sees this).
    pub record: Option<std::path::PathBuf>,
    /// `--record-filter PATTERN` (repeatable, needs `--record`): only outputs whose
    /// path (`module/port`) matches; `*` matches any characters.
    pub record_filter: Vec<String>,
    /// `--force`: `--record` and loggers may replace an existing file that is not a
    /// ferroc recording.
    pub force: bool,
    /// `--inspect [ADDR]`: serve live inspection over Zenoh on ADDR (default
    /// 127.0.0.1:47900; docs/inspect.md), read with `ferroc inspect`.
    pub inspect: Option<String>,
    /// `--inspect-public`: allow `--inspect` on an address other computers can reach.
    pub inspect_public: bool,
}

impl Args {
    /// Parses the process's arguments. On `--help` prints `about` and the options and
    /// returns exit code 0; on a bad argument explains it and returns exit code 2.
    pub fn from_env(program: &str, about: &str) -> Result<Args, ExitCode> {
        let args: Vec<String> = std::env::args().skip(1).collect();
        match Args::parse(&args) {
            Ok(Some(args)) => Ok(args),
            Ok(None) => {
                println!("{about}\n\n{}", usage(program));
                Err(ExitCode::SUCCESS)
            }
            Err(e) => {
                eprintln!("error: {e}\n\n{}", usage(program));
                Err(ExitCode::from(2))
            }
        }
    }

    /// Parses arguments (without the program name); `Ok(None)` means help was asked for.
    pub fn parse(args: &[String]) -> Result<Option<Args>, String> {
        let mut out = Args::default();
        let mut it = args.iter().peekable();
        while let Some(arg) = it.next() {
            let (name, inline) = match arg.split_once('=') {
                Some((n, v)) if n.starts_with("--") => (n, Some(v.to_string())),
                _ => (arg.as_str(), None),
            };
            let mut value = |what: &str| {
                inline
                    .clone()
                    .or_else(|| it.next().cloned())
                    .ok_or_else(|| format!("`{name}` needs a value: {what}"))
            };
            match name {
                "-h" | "--help" => return Ok(None),
                "-q" | "--quiet" => out.quiet = true,
                "--cycles" => {
                    let v = value("a number of cycles, e.g. --cycles 100")?;
                    out.cycles = Some(v.parse().map_err(|_| {
                        format!("--cycles {v}: not a number of cycles (write e.g. 100)")
                    })?);
                }
                "--for" => {
                    let v = value("a duration, e.g. --for 10s")?;
                    out.duration = Some(parse_duration(&v)?);
                }
                "--lockstep" => out.lockstep = true,
                "--force" => out.force = true,
                "--local" => out.local = true,
                "--peer" => {
                    let v = value("a part and its address, e.g. --peer station=10.0.0.2:47801")?;
                    let (part, address) = v
                        .split_once('=')
                        .filter(|(p, a)| !p.is_empty() && a.contains(':'))
                        .ok_or_else(|| format!("--peer {v}: write PART=HOST:PORT"))?;
                    out.peers.push((part.to_owned(), address.to_owned()));
                }
                "--listen" => {
                    let v = value("an address, e.g. --listen 0.0.0.0:47801")?;
                    out.listen = Some(v);
                }
                "--zenoh-config" => {
                    let v = value("a Zenoh configuration file, e.g. --zenoh-config zenoh.json5")?;
                    out.zenoh_config = Some(v.into());
                }
                "--record" => {
                    let v = value("an MCAP file, e.g. --record run.mcap")?;
                    out.record = Some(v.into());
                }
                "--inspect" => {
                    // The address is optional: the next argument unless it is an option.
                    let next = it.next_if(|a| !a.starts_with('-')).cloned();
                    out.inspect = Some(
                        inline
                            .clone()
                            .or(next)
                            .unwrap_or_else(|| "127.0.0.1:47900".into()),
                    );
                }
                "--inspect-public" => out.inspect_public = true,
                "--record-filter" => {
                    let v = value("a pattern of output paths, e.g. --record-filter 'robot/*'")?;
                    out.record_filter.push(v);
                }
                _ => return Err(format!("unknown argument `{arg}`")),
            }
        }
        if out.inspect.is_none() && out.inspect_public {
            return Err("--inspect-public needs --inspect: it allows its address".into());
        }
        if out.record.is_none() && !out.record_filter.is_empty() {
            return Err("--record-filter needs --record FILE: it says what to record".into());
        }
        Ok(Some(out))
    }

    /// How to start a part of an application whose periodic containers have
    /// `periods` (lockstep). The network to the other parts is added by the caller
    /// (from [`Args::addresses`]).
    pub fn start_options(&self, periods: &[Duration]) -> crate::builder::StartOptions {
        crate::builder::StartOptions {
            limit: self.cycles,
            lockstep: self.lockstep.then(|| crate::builder::Lockstep {
                periods: periods.to_vec(),
                until: self.duration,
            }),
            network: None,
        }
    }

    /// Where the part `part` listens and where the others are, for an application
    /// whose parts listen at `parts` (name, `host:port`), as `--local`, `--peer` and
    /// `--listen` say.
    pub fn addresses(
        &self,
        part: &str,
        parts: &[(&str, &str)],
    ) -> Result<ferroc_link::transport::Addresses, String> {
        let mut peers: std::collections::BTreeMap<String, String> = parts
            .iter()
            .map(|(name, address)| {
                let address = match address.rsplit_once(':') {
                    Some((_, port)) if self.local => format!("127.0.0.1:{port}"),
                    _ => address.to_string(),
                };
                (name.to_string(), address)
            })
            .collect();
        for (name, address) in &self.peers {
            if !peers.contains_key(name) {
                let known: Vec<&str> = parts.iter().map(|(n, _)| *n).collect();
                return Err(format!(
                    "--peer {name}=…: the application has no part `{name}` (its parts: {})",
                    known.join(", ")
                ));
            }
            peers.insert(name.clone(), address.clone());
        }
        let own_port = peers
            .get(part)
            .and_then(|a| a.rsplit_once(':'))
            .map(|(_, port)| port.to_owned())
            .unwrap_or_else(|| "0".into());
        let listen = self.listen.clone().unwrap_or_else(|| {
            let any = if self.local { "127.0.0.1" } else { "0.0.0.0" };
            format!("{any}:{own_port}")
        });
        Ok(ferroc_link::transport::Addresses {
            part: part.to_owned(),
            listen,
            peers,
        })
    }

    /// The supervision options these arguments ask for (status line only on a terminal;
    /// in lockstep `--for` is model time, which the lockstep driver counts itself).
    pub fn options(&self) -> Options {
        Options {
            duration: self.duration.filter(|_| !self.lockstep),
            status_line: !self.quiet && std::io::stderr().is_terminal(),
        }
    }
}

fn usage(program: &str) -> String {
    format!(
        "Usage: {program} [--cycles N] [--for DURATION] [--lockstep] [--local] [--peer PART=HOST:PORT]...\n       \
         [--listen ADDR] [--zenoh-config FILE] [--record FILE [--record-filter PATTERN]...]\n       \
         [--force] [--inspect [ADDR] [--inspect-public]] [--quiet]\n\n\
         Options:\n  \
         --cycles N        stop after N cycles of the application: of its fastest\n                    \
         periodic thread containers; slower ones run until then\n  \
         --for DURATION    stop after this long: 500ms, 10s, 2min, 1h (model time in\n                    \
         lockstep)\n  \
         --lockstep        run in simulated time, in step with the other parts: the same\n                    \
         output on every run, and the same as `ferroc run --lockstep`\n  \
         --local           every part runs on this computer (127.0.0.1, same ports)\n  \
         --peer PART=HOST:PORT\n                    \
         where another part listens (default: its host and port in the model)\n  \
         --listen ADDR     where this part listens (default: its port on all interfaces)\n  \
         --zenoh-config FILE\n                    \
         Zenoh's own configuration (JSON5): routers, scouting, access control;\n                    \
         merged with ferroc's defaults and the addresses above (the file wins)\n  \
         --record FILE     record every output of this program's modules that feeds a\n                    \
         connection into an MCAP file (as `ferroc run --record`)\n  \
         --record-filter PATTERN\n                    \
         with --record: only outputs whose path (module/port) matches;\n                    \
         `*` matches any characters (repeatable)\n  \
         --force           let --record and loggers replace a file that is not a ferroc\n                    \
         recording (without it such a file is never overwritten)\n  \
         --inspect [ADDR]  serve live inspection over Zenoh on ADDR (default\n                    \
         127.0.0.1:47900): read it with `ferroc inspect`; changes need the\n                    \
         token printed at start\n  \
         --inspect-public  allow --inspect on an address other computers can reach\n  \
         -q, --quiet       no live status line\n  \
         -h, --help        this text\n\n\
         Ctrl-C or SIGTERM stops after the current cycle. A summary (cycles, overruns and\n\
         load per thread container) is printed on standard error at the end.\n\n\
         Exit codes: 0 stopped cleanly, 1 the application could not be built, a module\n\
         panicked or (in lockstep) a linked part is gone, 2 bad arguments, 3 the run\n\
         lost data it was meant to keep (a recording cut short, named in the summary)."
    )
}

/// `500ms`, `10s`, `1.5 s`, `2min`, `1h`, `250us`.
pub fn parse_duration(text: &str) -> Result<Duration, String> {
    let t = text.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (number, unit) = (&t[..split], t[split..].trim());
    let scale = match unit {
        "us" | "µs" => 1e-6,
        "ms" => 1e-3,
        "s" => 1.0,
        "min" => 60.0,
        "h" => 3600.0,
        _ => f64::NAN,
    };
    match number.parse::<f64>() {
        Ok(n) if scale.is_finite() && (n * scale).is_finite() && n * scale <= 1e9 => {
            Ok(Duration::from_secs_f64(n * scale))
        }
        _ => Err(format!(
            "`{text}` is not a duration; write e.g. 10s, 500ms or 2min"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(args: &[&str]) -> Result<Option<Args>, String> {
        Args::parse(&args.iter().map(|s| s.to_string()).collect::<Vec<_>>())
    }

    #[test]
    fn arguments_of_a_generated_program() {
        let args = parse(&["--cycles", "20", "-q", "--for=1.5s"])
            .unwrap()
            .unwrap();
        assert_eq!(args.cycles, Some(20));
        assert!(args.quiet);
        assert_eq!(args.duration, Some(Duration::from_millis(1500)));
        assert_eq!(parse(&["--help"]), Ok(None));
        assert!(parse(&["--cycles"]).unwrap_err().contains("needs a value"));
        assert!(parse(&["--cycles", "x"])
            .unwrap_err()
            .contains("not a number"));
        assert!(parse(&["--for", "soon"])
            .unwrap_err()
            .contains("not a duration"));
        assert!(parse(&["--bogus"])
            .unwrap_err()
            .contains("unknown argument"));
        let args = parse(&[
            "--lockstep",
            "--local",
            "--peer",
            "b=10.0.0.2:9",
            "--zenoh-config",
            "z.json5",
        ])
        .unwrap()
        .unwrap();
        let parts = [("a", "robot-pc:47800"), ("b", "base-pc:47801")];
        let network = args.addresses("a", &parts).unwrap();
        assert_eq!(network.listen, "127.0.0.1:47800");
        assert_eq!(network.peers["a"], "127.0.0.1:47800", "--local");
        assert_eq!(network.peers["b"], "10.0.0.2:9", "--peer wins");
        assert_eq!(args.zenoh_config.as_deref(), Some("z.json5".as_ref()));
        assert!(args.start_options(&[]).lockstep.is_some());
        let stranger = parse(&["--peer", "c=h:1"]).unwrap().unwrap();
        let err = stranger.addresses("a", &parts).unwrap_err();
        assert!(err.contains("no part `c`"), "{err}");
        assert!(parse(&["--peer", "nocolon"]).is_err());
        let record = parse(&["--record", "a.mcap", "--record-filter=robot/*"])
            .unwrap()
            .unwrap();
        assert_eq!(record.record.as_deref(), Some("a.mcap".as_ref()));
        assert_eq!(record.record_filter, ["robot/*"]);
        let alone = parse(&["--record-filter", "robot/*"]).unwrap_err();
        assert!(alone.contains("needs --record FILE"), "{alone}");
        // --inspect takes an address, or the default when an option follows.
        let inspect = |a: &[&str]| parse(a).unwrap().unwrap().inspect;
        assert_eq!(
            inspect(&["--inspect", "-q"]).as_deref(),
            Some("127.0.0.1:47900")
        );
        assert_eq!(inspect(&["--inspect"]).as_deref(), Some("127.0.0.1:47900"));
        assert_eq!(
            inspect(&["--inspect", "127.0.0.1:9"]).as_deref(),
            Some("127.0.0.1:9")
        );
        assert_eq!(inspect(&["--inspect=h:1", "-q"]).as_deref(), Some("h:1"));
        assert_eq!(inspect(&["-q"]), None);
        let public = parse(&["--inspect-public"]).unwrap_err();
        assert!(public.contains("needs --inspect"), "{public}");
        assert_eq!(
            parse_duration("2min"),
            Ok(Duration::from_secs(120)),
            "minutes"
        );
    }
}

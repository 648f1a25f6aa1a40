//! `--color auto|always|never`, one setting for the whole command line: the findings of
//! `check` (miette's colours), clap's help and usage errors, and cargo's output while
//! a runner is built. `auto` colours a terminal unless `NO_COLOR` is set (no-color.org);
//! `always` and `never` win over both.

use std::ffi::OsString;
use std::io::IsTerminal;
use std::sync::OnceLock;

/// When to colour what ferroc writes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum ColorChoice {
    /// On a terminal, unless NO_COLOR is set
    #[default]
    Auto,
    /// Always, also into a pipe or a file
    Always,
    /// Never
    Never,
}

/// Which of ferroc's streams a text goes to: `auto` asks whether that one is a terminal.
#[derive(Clone, Copy, Debug)]
pub enum Stream {
    Stdout,
    Stderr,
}

static CHOSEN: OnceLock<ColorChoice> = OnceLock::new();

/// Sets the command line's choice for this process (once, in `main`).
pub fn choose(choice: ColorChoice) {
    let _ = CHOSEN.set(choice);
}

/// Whether text written to `stream` is coloured, by the choice set in `main`.
pub fn enabled(stream: Stream) -> bool {
    CHOSEN.get().copied().unwrap_or_default().colours(stream)
}

impl ColorChoice {
    /// Whether to colour text written to `stream`.
    pub fn colours(self, stream: Stream) -> bool {
        let terminal = match stream {
            Stream::Stdout => std::io::stdout().is_terminal(),
            Stream::Stderr => std::io::stderr().is_terminal(),
        };
        self.colours_when(terminal, no_color())
    }

    /// The rule itself: `auto` colours a terminal without NO_COLOR.
    fn colours_when(self, terminal: bool, no_color: bool) -> bool {
        match self {
            ColorChoice::Always => true,
            ColorChoice::Never => false,
            ColorChoice::Auto => terminal && !no_color,
        }
    }

    /// The choice in a command line clap could not parse (`--help`, `--version`, a
    /// usage error end parsing before the flag is read): the last `--color X` or
    /// `--color=X` before `--`; `auto` when there is none or it is not a choice.
    pub fn from_args(args: impl IntoIterator<Item = OsString>) -> ColorChoice {
        let mut chosen = ColorChoice::Auto;
        let mut args = args.into_iter().map(|a| a.to_string_lossy().into_owned());
        while let Some(arg) = args.next() {
            let value = match arg.as_str() {
                "--" => break,
                "--color" => args.next(),
                other => other.strip_prefix("--color=").map(str::to_owned),
            };
            if let Some(v) = value {
                chosen = <ColorChoice as clap::ValueEnum>::from_str(&v, true).unwrap_or(chosen);
            }
        }
        chosen
    }
}

/// NO_COLOR set to anything but the empty string (no-color.org).
fn no_color() -> bool {
    std::env::var_os("NO_COLOR").is_some_and(|v| !v.is_empty())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn auto_colours_a_terminal_without_no_color_and_the_flags_win() {
        assert!(ColorChoice::Auto.colours_when(true, false));
        assert!(!ColorChoice::Auto.colours_when(true, true));
        assert!(!ColorChoice::Auto.colours_when(false, false));
        assert!(ColorChoice::Always.colours_when(false, true));
        assert!(!ColorChoice::Never.colours_when(true, false));
    }

    #[test]
    fn the_choice_is_read_from_a_command_line_clap_refused() {
        let args = |a: &[&str]| a.iter().map(OsString::from).collect::<Vec<_>>();
        let read = |a: &[&str]| ColorChoice::from_args(args(a));
        assert_eq!(read(&["check", "--help"]), ColorChoice::Auto);
        assert_eq!(
            read(&["--color", "never", "check", "--help"]),
            ColorChoice::Never
        );
        assert_eq!(
            read(&["check", "--color=always", "-x"]),
            ColorChoice::Always
        );
        assert_eq!(read(&["check", "--color", "purple"]), ColorChoice::Auto);
        assert_eq!(read(&["run", "--", "--color", "never"]), ColorChoice::Auto);
    }
}

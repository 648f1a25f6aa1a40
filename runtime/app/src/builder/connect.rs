//! Data connections by name, with the converters a connection needs between the
//! writer's output and the reader's input.

use super::{convert, find, BuildError, Builder, Conversion, Instance, LocalClaim, Select};
use ferroc_ports::port::{ConnectOptions, Home};

impl Builder<'_> {
    /// Connects `from` (module path, output name) to `to` (module path, input name),
    /// converting values on the way if `conversion` is not the identity or the value
    /// types differ (numbers only).
    pub fn connect(
        &mut self,
        from: (&str, &str),
        to: (&str, &str),
        conversion: Conversion,
        options: ConnectOptions,
    ) -> Result<(), BuildError> {
        let (writer, reader) = (self.module(from.0)?, self.module(to.0)?);
        let output = find(&self.modules[writer].outputs, from, "output")?;
        let input = find(&self.modules[reader].inputs, to, "input")?;
        let describe = || format!("`{}/{}` → `{}/{}`", from.0, from.1, to.0, to.1);
        if conversion.is_identity() && output.value_type() == input.value_type() {
            output
                .connect(input, options)
                .map_err(|e| BuildError::Connect(format!("{}: {e}", describe())))?;
            self.connections.push((writer, reader, to.1.to_owned()));
            if options.local {
                let pair = output.local_pair(input);
                self.claim_local(writer, reader, describe(), pair);
            }
            self.note_reader(writer, from.1, reader);
            return Ok(());
        }
        // A chain of converters: each selected part, then the numeric change.
        let name = format!("{}/{} → {}/{}", from.0, from.1, to.0, to.1);
        let mut chain: Vec<convert::Converter> = Vec::new();
        for select in &conversion.select {
            let value_type = chain
                .last()
                .map_or(output.value_type(), |c| c.output.value_type());
            let (part, index, what) = match select {
                Select::Field(f) => (f.as_str(), 0, format!("the field `{f}`")),
                Select::Index(i) => ("[]", *i, format!("element {i}")),
            };
            let make = self.registry.part(value_type, part).ok_or_else(|| {
                BuildError::Connect(format!(
                    "{}: cannot take {what} of {value_type}: no library registered it \
                     (its crate's register function should call `register_field` or \
                     `register_index` for it)",
                    describe()
                ))
            })?;
            chain.push(make(format!("{name} ({what})"), index));
        }
        let selected = chain
            .last()
            .map_or(output.value_type(), |c| c.output.value_type());
        if conversion.scales() || selected != input.value_type() {
            let numeric = convert::numeric(selected, input.value_type(), name, conversion.clone())
                .ok_or_else(|| {
                    BuildError::Connect(format!(
                        "{}: cannot convert {selected} to {} (only numbers are converted)",
                        describe(),
                        input.value_type()
                    ))
                })?;
            chain.push(numeric);
        }
        let fail = |e: ferroc_ports::port::ConnectError| {
            BuildError::Connect(format!("{}: {e}", describe()))
        };
        let mut upstream = output;
        for converter in &chain {
            upstream
                .connect(&converter.input, ConnectOptions::default())
                .map_err(fail)?;
            upstream = &converter.output;
        }
        upstream.connect(input, options).map_err(fail)?;
        let steps = &mut self.modules[writer].converters;
        steps.extend(chain.into_iter().map(|c| c.step));
        self.connections.push((writer, reader, to.1.to_owned()));
        self.note_reader(writer, from.1, reader);
        if options.local {
            // Checked like the others, but the converters keep it on the lock-free path.
            self.claim_local(writer, reader, describe(), None);
        }
        Ok(())
    }

    fn claim_local(
        &mut self,
        writer: usize,
        reader: usize,
        name: String,
        pair: Option<ferroc_ports::port::LocalPair>,
    ) {
        self.local.push(LocalClaim {
            writer,
            reader,
            name,
            pair,
        });
    }

    /// Refuses connections marked as inside one thread container whose ends are not
    /// (the plan and the Builder calls disagree).
    pub(super) fn check_local_claims(&self) -> Result<(), BuildError> {
        for claim in &self.local {
            let (w, r) = (&self.modules[claim.writer], &self.modules[claim.reader]);
            if w.thread.is_some() && w.thread == r.thread {
                continue;
            }
            let container = |m: &Instance| match m.thread {
                Some(t) => format!("the thread container `{}`", self.threads[t].path),
                None => "no thread container".to_owned(),
            };
            return Err(BuildError::Connect(format!(
                "{} is marked as inside one thread container, but `{}` runs in {} and `{}` \
                 in {}; connect it without `ConnectOptions::local`",
                claim.name,
                w.path,
                container(w),
                r.path,
                container(r)
            )));
        }
        Ok(())
    }

    /// Makes the marked connections of thread container `thread` local to `home`; how
    /// many became local.
    pub(super) fn make_local(&self, thread: usize, home: &ferroc_ports::sync::Arc<Home>) -> usize {
        self.local
            .iter()
            .filter(|c| self.modules[c.writer].thread == Some(thread))
            .filter_map(|c| c.pair.as_ref())
            .filter(|pair| pair(home))
            .count()
    }
}

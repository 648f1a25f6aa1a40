//! Turning thread specs into running thread containers: each step calls its module,
//! converters run right after their writer, and a data-triggered container is woken
//! only by inputs fed from outside it.

use super::{BuildError, Builder, Schedule, StepKind};
use ferroc_exec::{Step, ThreadContainer, ThreadOptions, Trigger};
use ferroc_module::Module;
use ferroc_ports::port::{Notifier, Wakeup};
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

impl Builder<'_> {
    /// Turns each thread spec into a container whose steps call the modules.
    pub(super) fn containers(
        &mut self,
    ) -> Result<Vec<(ThreadContainer, ThreadOptions)>, BuildError> {
        // A sense-control module has two steps in one container: they share it behind
        // an uncontended mutex. A plain module is owned by its single step.
        let mut shared: HashMap<usize, Arc<Mutex<Box<dyn Module>>>> = HashMap::new();
        let threads = std::mem::take(&mut self.threads);
        let mut out = Vec::new();
        for (id, spec) in threads.into_iter().enumerate() {
            let wakeup = Wakeup::new();
            let mut steps = Vec::new();
            for (i, (path, kind)) in spec.steps.iter().enumerate() {
                let m = self.module(path)?;
                let instance = &mut self.modules[m];
                let name = format!("{path}:{}", step_name(*kind));
                match kind {
                    StepKind::Update => {
                        let module = instance.module.take().ok_or_else(|| {
                            BuildError::Thread(format!("`{path}` has two update steps"))
                        })?;
                        steps.push(Step::update(name, module));
                    }
                    StepKind::Sense | StepKind::Control => {
                        let cell = match shared.get(&m) {
                            Some(cell) => cell.clone(),
                            None => {
                                let module = instance.module.take().ok_or_else(|| {
                                    BuildError::Thread(format!("`{path}` has no module"))
                                })?;
                                let cell = Arc::new(Mutex::new(module));
                                shared.insert(m, cell.clone());
                                cell
                            }
                        };
                        let sense = *kind == StepKind::Sense;
                        steps.push(Step::new(name, move || {
                            // A panic in the other step poisons the lock: stop this
                            // one too rather than run on half-updated state.
                            let mut module = cell.lock().expect(
                                "the module's other step panicked; this step is stopped too",
                            );
                            if sense {
                                module.sense()
                            } else {
                                module.control()
                            }
                        }));
                    }
                }
                // Converters after the module's last step in this container.
                let last_of_module = !spec.steps[i + 1..].iter().any(|(p, _)| p == path);
                if last_of_module {
                    steps.append(&mut self.modules[m].converters);
                }
                if spec.schedule == Schedule::Data {
                    for (name, input) in &self.modules[m].inputs {
                        if self.fed_only_from_within(m, name) {
                            continue;
                        }
                        let notifier: Notifier = wakeup.clone();
                        let _ = input.set_notifier(notifier);
                    }
                    self.wake_on_calls(m, &wakeup);
                }
            }
            let trigger = match spec.schedule {
                Schedule::Periodic(period) => Trigger::Periodic(period),
                Schedule::Data => Trigger::Data(wakeup),
                Schedule::Continuous => Trigger::Continuous,
            };
            let container = ThreadContainer::new(spec.path, trigger, steps);
            self.make_local(id, container.home());
            out.push((container, spec.options));
        }
        Ok(out)
    }
}

impl Builder<'_> {
    /// Whether every known writer of `reader`'s input runs in the reader's own
    /// container (an input nobody in the model feeds may be fed from outside: it wakes).
    fn fed_only_from_within(&self, reader: usize, input: &str) -> bool {
        let thread = self.modules[reader].thread;
        let mut writers = self
            .connections
            .iter()
            .filter(|(_, r, name)| *r == reader && name == input)
            .peekable();
        writers.peek().is_some() && writers.all(|(w, ..)| self.modules[*w].thread == thread)
    }
}

fn step_name(kind: StepKind) -> &'static str {
    match kind {
        StepKind::Update => "update",
        StepKind::Sense => "sense",
        StepKind::Control => "control",
    }
}

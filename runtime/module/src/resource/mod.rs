//! Application resources: the model's `<resource>` locks as real locks.
//!
//! A module type declares the locks it takes (`m.lock("map")` in `create`, listed in
//! the manifest's `<locks order="…">`); the model binds each slot to an application
//! resource (`<bind lock resource>`, or the resource of the slot's name). Modules take
//! them with `self.map.lock()`, which returns a guard.
//!
//! Every acquisition is validated against the order graph ([`LockOrder`]): taking
//! locks in an order that contradicts an order seen before, or the declared one, is
//! reported at once with both acquisition sites — before it can deadlock. Levels
//! (`<resource level>`) must rise along every nesting. A thread taking a
//! non-recursive resource it already holds would wait for itself forever; that is
//! reported and the call panics instead (the container stops that module).

mod order;

pub use order::{LockOrder, Site};

use std::cell::RefCell;
use std::panic::Location;
use std::sync::{Arc, Condvar, Mutex, OnceLock};
use std::thread::ThreadId;

/// One application resource (a named lock).
pub struct Resource {
    name: String,
    id: usize,
    level: Option<u32>,
    recursive: bool,
    order: Arc<LockOrder>,
    owner: Mutex<Owner>,
    released: Condvar,
}

#[derive(Default)]
struct Owner {
    thread: Option<ThreadId>,
    depth: u32,
}

thread_local! {
    /// Resources this thread holds, in acquisition order: (order graph, id, site).
    static HELD: RefCell<Vec<(usize, usize, Site)>> = const { RefCell::new(Vec::new()) };
}

impl Resource {
    /// A resource registered in `order`.
    pub fn new(
        name: &str,
        level: Option<u32>,
        recursive: bool,
        order: &Arc<LockOrder>,
    ) -> Arc<Self> {
        Arc::new(Resource {
            name: name.to_string(),
            id: order.add(name, level),
            level,
            recursive,
            order: Arc::clone(order),
            owner: Mutex::new(Owner::default()),
            released: Condvar::new(),
        })
    }

    #[doc(hidden)]
    pub fn id(&self) -> usize {
        self.id
    }

    /// The resource's name in the model.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Takes the resource (waiting while another thread holds it), after validating
    /// the order against everything this thread holds. `module` names the taker.
    #[track_caller]
    pub fn lock(self: &Arc<Self>, module: &str) -> ResourceGuard {
        let site = Site {
            location: Location::caller(),
            module: module.to_string(),
            thread: std::thread::current()
                .name()
                .unwrap_or("unnamed")
                .to_string(),
        };
        let graph = self.order.serial();
        let held: Vec<(usize, Site)> = HELD.with(|h| {
            h.borrow()
                .iter()
                .filter(|(g, _, _)| *g == graph)
                .map(|(_, id, site)| (*id, site.clone()))
                .collect()
        });
        if let Some((_, first)) = held.iter().find(|(id, _)| *id == self.id) {
            if !self.recursive {
                let text = format!(
                    "recursive lock: `{}` is taken again by the thread that holds it; it would wait for itself forever\n  \
                     now:    taken at {site}\n  before: taken at {first}\n  \
                     help: release it first, or declare <resource name=\"{}\" kind=\"recursive\"/>",
                    self.name, self.name
                );
                self.order.report(text.clone());
                panic!("{text}");
            }
        } else {
            self.check_levels(&held, &site);
            self.order.check(&held, self.id, &site);
        }
        self.acquire();
        HELD.with(|h| h.borrow_mut().push((graph, self.id, site)));
        ResourceGuard {
            resource: Arc::clone(self),
        }
    }

    fn check_levels(&self, held: &[(usize, Site)], site: &Site) {
        let Some(level) = self.level else { return };
        for (id, held_site) in held {
            let Some((held_name, Some(held_level))) = self.order.describe_resource(*id) else {
                continue;
            };
            if level <= held_level {
                self.order.report(format!(
                    "lock level violation: `{}` (level {level}) is taken while holding `{}` (level {held_level}); levels must rise\n  \
                     now:    taken at {site}\n  held:   since {held_site}\n  \
                     help: take `{}` first, or fix the levels",
                    self.name, held_name, self.name
                ));
            }
        }
    }

    fn acquire(&self) {
        let me = std::thread::current().id();
        let mut owner = self.owner.lock().unwrap_or_else(|e| e.into_inner());
        while owner.thread.is_some_and(|t| t != me) {
            owner = self.released.wait(owner).unwrap_or_else(|e| e.into_inner());
        }
        owner.thread = Some(me);
        owner.depth += 1;
    }

    fn release(&self) {
        let mut owner = self.owner.lock().unwrap_or_else(|e| e.into_inner());
        owner.depth = owner.depth.saturating_sub(1);
        if owner.depth == 0 {
            owner.thread = None;
            drop(owner);
            self.released.notify_one();
        }
    }
}

/// Holds a resource until dropped.
pub struct ResourceGuard {
    resource: Arc<Resource>,
}

impl Drop for ResourceGuard {
    fn drop(&mut self) {
        let graph = self.resource.order.serial();
        let id = self.resource.id;
        HELD.with(|h| {
            let mut h = h.borrow_mut();
            if let Some(i) = h.iter().rposition(|(g, r, _)| *g == graph && *r == id) {
                h.remove(i);
            }
        });
        self.resource.release();
    }
}

/// A module's lock slot, bound to an application resource when the application is
/// built (`Builder::bind_lock`, or the resource of the slot's name).
pub struct LockSlot {
    pub(crate) slot: String,
    pub(crate) module: Arc<OnceLock<String>>,
    pub(crate) resource: Arc<OnceLock<Arc<Resource>>>,
}

impl LockSlot {
    /// Takes the bound resource; see [`Resource::lock`].
    ///
    /// # Panics
    /// If the slot was never bound (a module used outside a built application), or on
    /// a recursive acquisition of a non-recursive resource.
    #[track_caller]
    pub fn lock(&self) -> ResourceGuard {
        let Some(resource) = self.resource.get() else {
            panic!("lock slot `{}` is not bound to a resource", self.slot);
        };
        let module = self.module.get().map_or("?", String::as_str);
        resource.lock(module)
    }

    /// The slot's name in the manifest.
    pub fn name(&self) -> &str {
        &self.slot
    }
}

#[cfg(test)]
mod tests;

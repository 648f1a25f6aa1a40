//! Lock-order validation in the style of the Linux kernel's lockdep.
//!
//! Every time a thread takes resource B while holding A, the edge A → B is recorded
//! with where it happened. A new edge that closes a cycle with the edges seen so far
//! (or with the order the model declares) means two code paths take the same locks in
//! opposite orders: run concurrently, they can deadlock. That is reported at once, with
//! both acquisition sites, whether or not this run ever hangs. Each edge is checked
//! once per thread (a thread-local set of edges already known), so a lock taken in the
//! same order every cycle costs a hash lookup, not a global lock.

use std::cell::RefCell;
use std::collections::{HashMap, HashSet};
use std::panic::Location;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Where a lock was taken: the Rust source line and the module that did it.
#[derive(Clone, Debug)]
pub struct Site {
    /// Source location of the `lock()` call.
    pub location: &'static Location<'static>,
    /// Element path of the module (or what else took it).
    pub module: String,
    /// Name of the OS thread (the thread container).
    pub thread: String,
}

impl std::fmt::Display for Site {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} in `{}` (thread `{}`)",
            self.location, self.module, self.thread
        )
    }
}

/// How an ordered pair of resources came to be known.
#[derive(Clone, Debug)]
enum Evidence {
    /// The model declares it (`<locks order>` or resource levels); text says where.
    Declared(String),
    /// Observed at run time: `first` was held (taken at `held`) while `second` was
    /// taken at `taken`.
    Observed { held: Site, taken: Site },
}

/// The order graph of one application's resources, shared by all its threads.
pub struct LockOrder {
    /// Unique per graph (an address could be reused by a later graph and inherit the
    /// thread-local "already validated" marks of a dead one).
    serial: usize,
    inner: Mutex<Graph>,
}

impl Default for LockOrder {
    fn default() -> Self {
        static NEXT: AtomicUsize = AtomicUsize::new(0);
        LockOrder {
            serial: NEXT.fetch_add(1, Ordering::Relaxed),
            inner: Mutex::default(),
        }
    }
}

#[derive(Default)]
struct Graph {
    names: Vec<String>,
    levels: Vec<Option<u32>>,
    edges: HashMap<(usize, usize), Evidence>,
    next: HashMap<usize, Vec<usize>>,
    reported: HashSet<(usize, usize)>,
    reports: Vec<String>,
}

thread_local! {
    /// Edges this thread has already validated, per order graph (by serial).
    static KNOWN: RefCell<HashSet<(usize, usize, usize)>> = RefCell::new(HashSet::new());
}

impl LockOrder {
    /// An empty graph.
    pub fn new() -> Self {
        Self::default()
    }

    /// Identifies this graph among all graphs of the process.
    pub(crate) fn serial(&self) -> usize {
        self.serial
    }

    /// Registers a resource name; the id is its index.
    pub(crate) fn add(&self, name: &str, level: Option<u32>) -> usize {
        let mut g = self.graph();
        g.names.push(name.to_string());
        g.levels.push(level);
        g.names.len() - 1
    }

    /// Name and level of resource `id`.
    pub(crate) fn describe_resource(&self, id: usize) -> Option<(String, Option<u32>)> {
        let g = self.graph();
        Some((g.names.get(id)?.clone(), *g.levels.get(id)?))
    }

    /// Declares that `first` is taken before `second` (from the model).
    #[doc(hidden)]
    pub fn declare(&self, first: usize, second: usize, why: String) {
        let mut g = self.graph();
        g.insert(first, second, Evidence::Declared(why));
    }

    /// Validates taking `taking` (at `site`) while `held` (ids with their sites) are
    /// held. Reports every inversion once per pair of resources.
    pub(crate) fn check(&self, held: &[(usize, Site)], taking: usize, site: &Site) {
        let me = self.serial;
        for (h, held_site) in held {
            if *h == taking {
                continue;
            }
            let new = KNOWN.with(|k| k.borrow_mut().insert((me, *h, taking)));
            if !new {
                continue;
            }
            let mut g = self.graph();
            if g.edges.contains_key(&(*h, taking)) {
                continue;
            }
            if let Some(path) = g.path(taking, *h) {
                let pair = (taking.min(*h), taking.max(*h));
                if g.reported.insert(pair) {
                    let report = g.describe(*h, held_site, taking, site, &path);
                    g.reports.push(report);
                }
            }
            g.insert(
                *h,
                taking,
                Evidence::Observed {
                    held: held_site.clone(),
                    taken: site.clone(),
                },
            );
        }
    }

    /// Every inversion reported so far.
    pub fn reports(&self) -> Vec<String> {
        self.graph().reports.clone()
    }

    /// Adds a report made elsewhere (a level violation, a recursive lock).
    pub(crate) fn report(&self, text: String) {
        self.graph().reports.push(text);
    }

    fn graph(&self) -> std::sync::MutexGuard<'_, Graph> {
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }
}

impl Graph {
    fn insert(&mut self, a: usize, b: usize, evidence: Evidence) {
        if self.edges.insert((a, b), evidence).is_none() {
            self.next.entry(a).or_default().push(b);
        }
    }

    /// A path of known edges from `from` to `to` (breadth first: the shortest).
    fn path(&self, from: usize, to: usize) -> Option<Vec<usize>> {
        let mut parent: HashMap<usize, usize> = HashMap::new();
        let mut queue = std::collections::VecDeque::from([from]);
        while let Some(n) = queue.pop_front() {
            if n == to {
                let mut path = vec![to];
                let mut cur = to;
                while cur != from {
                    cur = parent[&cur];
                    path.push(cur);
                }
                path.reverse();
                return Some(path);
            }
            for &m in self.next.get(&n).into_iter().flatten() {
                if m != from && !parent.contains_key(&m) {
                    parent.insert(m, n);
                    queue.push_back(m);
                }
            }
        }
        None
    }

    fn describe(
        &self,
        held: usize,
        held_site: &Site,
        taking: usize,
        site: &Site,
        path: &[usize],
    ) -> String {
        let name = |i: usize| self.names.get(i).map_or("?", String::as_str);
        let mut text = format!(
            "lock order inversion: `{}` is taken while holding `{}`, the opposite of an order seen before; \
             run concurrently, these paths can deadlock\n  \
             now:    `{}` taken at {site}\n          while `{}` held since {held_site}",
            name(taking),
            name(held),
            name(taking),
            name(held),
        );
        for pair in path.windows(2) {
            let (a, b) = (pair[0], pair[1]);
            match &self.edges[&(a, b)] {
                Evidence::Observed { held, taken } => text.push_str(&format!(
                    "\n  before: `{}` taken at {taken}\n          while `{}` held since {held}",
                    name(b),
                    name(a)
                )),
                Evidence::Declared(why) => text.push_str(&format!(
                    "\n  declared: `{}` before `{}` ({why})",
                    name(a),
                    name(b)
                )),
            }
        }
        text.push_str(&format!(
            "\n  help: take `{}` and `{}` in one order everywhere (and declare it with <locks order>)",
            name(path[0]),
            name(path[path.len() - 1])
        ));
        text
    }
}

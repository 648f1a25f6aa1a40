//! Where everything of the B1 model goes, computed once from N: groups → thread
//! containers → parts, which container of a block serves the others (the hub), and
//! what each group is. The generator only reads it.

/// Thread containers per block: one hub serves the other nine (clients, locks).
pub(super) const BLOCK: usize = 10;

/// What a group is. All kinds have the same interface ports and internal wiring; the
/// kinds that can wait replace some `ferroc_std` modules by `b1` ones with the same
/// port names (`b1.lib.xml`).
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(super) enum GroupKind {
    /// Content written out in place, with parameters of its own.
    Inline,
    /// `type="local.Filter"`: one definition, many instances.
    Instance,
    /// First group of a container fed by the ring's queue: reads it blocking, with a
    /// timeout (`b1.Inbox`).
    Inbox,
    /// Calls its hub's map server (blocking without timeout, async, with a timeout) and
    /// its own calibration service inline (`executes="caller"`).
    Client,
    /// Takes its block's `map` and `pose` locks in the declared order (`b1.Estimator`).
    Locking,
    /// The hub's first group: the map server (services, the same two locks).
    Server,
}

/// The model's shape; depends on N alone.
pub(super) struct Layout {
    pub groups: usize,
    pub threads: usize,
    pub parts: usize,
    /// The first group of each thread container.
    first_of_thread: Vec<usize>,
}

impl Layout {
    pub fn new(n_modules: usize) -> Self {
        let groups = n_modules.div_ceil(super::GROUP_SIZE).max(1);
        let threads = (groups / 10).max(1);
        let parts = (n_modules / 5000).clamp(1, threads);
        let mut first_of_thread = vec![0; threads];
        for g in (0..groups).rev() {
            first_of_thread[g * threads / groups] = g;
        }
        Layout {
            groups,
            threads,
            parts,
            first_of_thread,
        }
    }

    pub fn thread_of(&self, group: usize) -> usize {
        group * self.threads / self.groups
    }

    pub fn part_of(&self, thread: usize) -> usize {
        thread * self.parts / self.threads
    }

    /// The group's index inside its thread container (`g3`).
    pub fn local(&self, group: usize) -> usize {
        group - self.first_of_thread[self.thread_of(group)]
    }

    /// Blocks of [`BLOCK`] containers (the last one may be shorter).
    pub fn blocks(&self) -> usize {
        self.threads.div_ceil(BLOCK)
    }

    /// The container serving `thread`'s block: its last one.
    pub fn hub_of(&self, thread: usize) -> usize {
        (thread / BLOCK * BLOCK + BLOCK - 1).min(self.threads - 1)
    }

    pub fn is_hub(&self, thread: usize) -> bool {
        self.hub_of(thread) == thread
    }

    /// Data-triggered containers: the ninth of every ten (each one a hub). Hubs declare
    /// no priority, so no periodic client waits on a lower priority (no S107).
    pub fn data_triggered(&self, thread: usize) -> bool {
        thread % BLOCK == BLOCK - 1
    }

    /// Priority of a periodic container that is not a hub: one per block, so waits
    /// inside a block never go to a lower priority.
    pub fn priority(&self, thread: usize) -> Option<usize> {
        (!self.is_hub(thread)).then_some(20 + (thread / BLOCK) % 60)
    }

    pub fn kind(&self, group: usize) -> GroupKind {
        let t = self.thread_of(group);
        let first = self.local(group) == 0;
        if self.is_hub(t) {
            // A hub never waits itself: a client there would call its own container.
            return match (first, group % 4) {
                (true, _) => GroupKind::Server,
                (false, 3) => GroupKind::Instance,
                _ => GroupKind::Inline,
            };
        }
        // The first container of a block reads the ring without waiting, so the ring
        // of blocking reads (with timeouts) over all containers is broken there.
        if first && t % BLOCK != 0 {
            return GroupKind::Inbox;
        }
        match group % 4 {
            1 => GroupKind::Client,
            2 => GroupKind::Locking,
            3 => GroupKind::Instance,
            _ => GroupKind::Inline,
        }
    }

    /// Application-level path of a group: `p1/t57/g3`.
    pub fn path(&self, group: usize) -> String {
        let t = self.thread_of(group);
        format!("p{}/t{t}/g{}", self.part_of(t), self.local(group))
    }

    /// Path of the map server module serving `thread`.
    pub fn server_of(&self, thread: usize) -> String {
        let hub = self.hub_of(thread);
        format!("{}/smooth", self.path(self.first_of_thread[hub]))
    }
}

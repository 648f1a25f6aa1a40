//! Which connections stay inside one thread container: the runtime keeps their value
//! in a cell only that container's thread touches (no atomics on the cycle path), and
//! changes them only at that container's cycle boundaries.

use super::Plan;
use std::collections::HashMap;

/// Marks every connection whose writer and reader modules run in the same thread
/// container (and which is not a link between parts) as local.
pub(super) fn mark_local(plan: &mut Plan) {
    let mut container: HashMap<&str, usize> = HashMap::new();
    for (i, thread) in plan.threads.iter().enumerate() {
        for (path, _) in &thread.steps {
            container.insert(path.as_str(), i);
        }
    }
    let local: Vec<bool> = (plan.connections.iter())
        .map(|c| {
            let writer = container.get(c.from.0.as_str());
            c.link.is_none() && writer.is_some() && writer == container.get(c.to.0.as_str())
        })
        .collect();
    for (c, local) in plan.connections.iter_mut().zip(local) {
        c.local = local;
    }
}

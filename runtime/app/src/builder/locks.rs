//! Application resources and their locks: resources with levels, declared lock orders,
//! and the binding of modules' lock slots to resources.

use super::{BuildError, Builder};
use ferroc_module::resource::Resource;
use std::sync::Arc;

impl Builder<'_> {
    /// Declares an application resource (`<resource name level kind>`).
    pub fn add_resource(
        &mut self,
        name: &str,
        level: Option<u32>,
        recursive: bool,
    ) -> Result<(), BuildError> {
        if self.resources.contains_key(name) {
            return Err(BuildError::Resource(format!(
                "the resource `{name}` is added twice"
            )));
        }
        let resource = Resource::new(name, level, recursive, &self.lock_order);
        self.resources.insert(name.to_owned(), resource);
        Ok(())
    }

    /// Declares that resource `first` is taken before `second` (a module type's
    /// `<locks order>`); `why` says where, for reports. Taking them the other way
    /// round is then reported the first time it happens.
    pub fn declare_lock_order(
        &mut self,
        first: &str,
        second: &str,
        why: &str,
    ) -> Result<(), BuildError> {
        let id = |name: &str| {
            self.resources
                .get(name)
                .map(|r| r.id())
                .ok_or_else(|| BuildError::Resource(format!("there is no resource `{name}`")))
        };
        let (a, b) = (id(first)?, id(second)?);
        self.lock_order.declare(a, b, why.to_owned());
        Ok(())
    }

    /// Binds a module's lock slot to an application resource (`<bind lock resource>`).
    /// Slots left unbound use the resource of the slot's name, created if needed.
    pub fn bind_lock(&mut self, path: &str, slot: &str, resource: &str) -> Result<(), BuildError> {
        let m = self.module(path)?;
        let Some(r) = self.resources.get(resource).cloned() else {
            return Err(BuildError::Resource(format!(
                "`{path}`: there is no resource `{resource}` to bind the lock slot `{slot}` to"
            )));
        };
        let Some(binding) = self.modules[m].locks.iter().find(|l| l.slot == slot) else {
            return Err(BuildError::Resource(format!(
                "`{path}` has no lock slot `{slot}`"
            )));
        };
        if binding.resource.set(r).is_err() {
            return Err(BuildError::Resource(format!(
                "`{path}`: the lock slot `{slot}` is bound twice"
            )));
        }
        Ok(())
    }

    /// Binds every slot not bound yet to the resource of its name.
    pub(super) fn bind_remaining_locks(&mut self) {
        for m in &self.modules {
            for binding in &m.locks {
                let _ = binding.module.set(m.path.clone());
                if binding.resource.get().is_none() {
                    let r = self
                        .resources
                        .entry(binding.slot.clone())
                        .or_insert_with(|| {
                            Resource::new(&binding.slot, None, false, &self.lock_order)
                        });
                    let _ = binding.resource.set(Arc::clone(r));
                }
            }
        }
    }
}

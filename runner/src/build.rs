//! A plan made into the runtime's `Builder` calls: every module, lock, connection,
//! call and thread container declared (the bundle writes the same calls as source).

use crate::from_plan::{conversion, link_spec, ports_of, queues_of, step_kind, thread_options};
use crate::plan::RunPlan as Plan;
use ferroc_runtime::behaviour::ViolationPolicy;
use ferroc_runtime::builder::{
    BuildError, Builder, Conversion, ModuleSpec, Registry, RunningApp, Schedule, StartOptions,
    ThreadSpec,
};
use ferroc_runtime::link::CallSpec;
use ferroc_runtime::port::ConnectOptions;
use std::time::Duration;

/// The Builder calls for a plan, then the start. Every part runs in this process;
/// connections between parts still travel as links (their values encoded, paced by
/// their `sharing=`), as they will between programs.
pub fn build(
    plan: &Plan,
    registry: &Registry,
    seed: u64,
    start: StartOptions,
) -> Result<RunningApp, BuildError> {
    builder(plan, registry, seed)?.start_with(start)
}

/// The Builder calls of [`build`] up to the start: a Builder with every module,
/// connection, call and thread container of the plan declared; the modules' random
/// sources derived from the run `seed`.
pub fn builder<'r>(
    plan: &Plan,
    registry: &'r Registry,
    seed: u64,
) -> Result<Builder<'r>, BuildError> {
    let mut builder = Builder::new(registry);
    builder.set_seed(seed);
    add_modules(&mut builder, plan)?;
    add_locks(&mut builder, plan)?;
    // The ROS 2 ends before the connections: a recorder of a subscribed input
    // (`--record`) is connected to its topic's receiving end.
    for node in &plan.ros2 {
        builder.ros2_node(node.clone())?;
    }
    connect_data(&mut builder, plan)?;
    connect_params(&mut builder, plan)?;
    connect_calls(&mut builder, plan)?;
    add_threads(&mut builder, plan)?;
    Ok(builder)
}

fn add_modules(builder: &mut Builder<'_>, plan: &Plan) -> Result<(), BuildError> {
    for m in &plan.modules {
        let (queues, ports) = (queues_of(m), ports_of(m));
        builder.add_module(ModuleSpec {
            path: &m.path,
            type_name: &m.type_name,
            params: &m.params,
            queues: &queues,
            ports: &ports,
            violations: ViolationPolicy::parse(&m.ib2c_violations).unwrap_or_default(),
        })?;
    }
    Ok(())
}

/// Lock resources, the slots bound to them, and the declared lock orders.
fn add_locks(builder: &mut Builder<'_>, plan: &Plan) -> Result<(), BuildError> {
    for (name, level, recursive) in &plan.locks.resources {
        builder.add_resource(name, *level, *recursive)?;
    }
    for (path, slot, resource) in &plan.locks.binds {
        builder.bind_lock(path, slot, resource)?;
    }
    for (first, second, why) in &plan.locks.orders {
        // A slot without <bind> or <resource> names its own resource.
        for name in [first, second] {
            if !plan.locks.resources.iter().any(|(r, _, _)| r == name) {
                let _ = builder.add_resource(name, None, false);
            }
        }
        builder.declare_lock_order(first, second, why)?;
    }
    Ok(())
}

/// Module-to-module connections: inside a part connected, between parts linked.
fn connect_data(builder: &mut Builder<'_>, plan: &Plan) -> Result<(), BuildError> {
    for c in &plan.connections {
        let (from, to) = (
            (c.from.0.as_str(), c.from.1.as_str()),
            (c.to.0.as_str(), c.to.1.as_str()),
        );
        match &c.link {
            None => {
                let options = ConnectOptions::default().with_local(c.local);
                builder.connect(from, to, conversion(c), options)?
            }
            Some(link) => {
                let spec = link_spec(link);
                builder.link_out(&spec, from, conversion(c))?;
                builder.link_in(&spec, to, ConnectOptions::default())?;
            }
        }
    }
    Ok(())
}

/// Outputs driving parameters: inside a part connected, between parts linked.
fn connect_params(builder: &mut Builder<'_>, plan: &Plan) -> Result<(), BuildError> {
    for link in &plan.param_links {
        let (from, to) = (
            (link.from.0.as_str(), link.from.1.as_str()),
            (link.to.0.as_str(), link.to.1.as_str()),
        );
        let scale = Conversion::linear(link.scale, 0.0);
        match &link.link {
            None => builder.connect_param(from, to, scale)?,
            Some(between) => {
                let spec = link_spec(between);
                builder.link_out(&spec, from, scale)?;
                builder.link_in_param(&spec, to)?;
            }
        }
    }
    Ok(())
}

/// Client → service calls.
fn connect_calls(builder: &mut Builder<'_>, plan: &Plan) -> Result<(), BuildError> {
    for call in &plan.calls {
        let (client, service) = (
            (call.client.0.as_str(), call.client.1.as_str()),
            (call.service.0.as_str(), call.service.1.as_str()),
        );
        match &call.link {
            // Between parts, as between the bundle's programs; types the libraries
            // did not register for crossing are called directly (one process).
            Some(link) if builder.can_call_across(client) => {
                let service_key = format!("{}/{}", service.0, service.1);
                let spec = CallSpec {
                    id: link.id,
                    client_part: &link.client_part,
                    server_part: &link.server_part,
                    service: &service_key,
                };
                builder.call_out(&spec, client)?;
                builder.call_in(&spec, service)?;
            }
            _ => builder.connect_service(client, service)?,
        }
    }
    Ok(())
}

/// Thread containers with their schedule, options and step order.
fn add_threads(builder: &mut Builder<'_>, plan: &Plan) -> Result<(), BuildError> {
    for t in &plan.threads {
        builder.add_thread(ThreadSpec {
            path: t.path.clone(),
            schedule: match (t.period, t.continuous) {
                (Some(p), _) => Schedule::Periodic(Duration::from_secs_f64(p)),
                (None, true) => Schedule::Continuous,
                (None, false) => Schedule::Data,
            },
            options: thread_options(t),
            steps: t
                .steps
                .iter()
                .map(|(path, kind)| (path.clone(), step_kind(*kind)))
                .collect(),
        })?;
    }
    Ok(())
}

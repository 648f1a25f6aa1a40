//! Checks of FINROC files as they are (area F, and L106/L107 of make.xml): application and group files, config
//! files and their links. They run on the readers' models in `crate`, not on
//! the IR: FINROC's files describe only what finstruct created, so most facts come from
//! the catalogue of component types (`crate::catalogue`). What a check could not
//! judge (a type not in the catalogue, no config file in the checkout) is listed as
//! "not checked" rather than guessed.

pub mod f101_finroc_structure;
pub mod f102_edge_end_missing;
pub mod f103_duplicate_edge;
pub mod f104_sensor_controller_mix;
pub mod f105_group_output_unwritten;
pub mod f106_config_value_unparsable;
pub mod f107_lookup_keys_not_monotonic;
pub mod f108_config_link_missing;
pub mod f109_dependency_missing;
pub mod f110_unknown_component_type;
pub mod f111_edge_type_mismatch;
pub mod f112_library_not_built;
pub mod f113_parameter_link_target_missing;
pub mod f114_edge_to_itself;
pub mod l106_make_cycle;
pub mod l107_duplicate_make_lib;

use crate::catalogue::Catalogue;
use crate::checkout::Checkout;
use crate::config::ConfigFile;
use crate::finstructable::{Edge, Finstructable};
use crate::resolve::{self, End, Scope};
use ferroc_diagnostics::diagnostic::Diagnostics;
use ferroc_diagnostics::source::SourceMap;
use std::collections::{BTreeMap, HashMap};
use std::path::Path;

/// What the structure checks see.
pub struct Context<'a> {
    pub doc: &'a Finstructable,
    pub path: &'a Path,
    pub checkout: &'a Checkout,
    pub catalogue: &'a Catalogue,
    pub sources: &'a SourceMap,
}

/// Facts several checks share, computed once.
pub struct Facts<'a> {
    pub scope: Scope<'a>,
    /// Both ends of each edge, resolved.
    pub ends: Vec<(End, End)>,
    /// For each edge that repeats an earlier one: (earlier edge, reversed?).
    pub duplicate_of: HashMap<usize, (usize, bool)>,
}

/// An edge's identity once FINROC has read it: scheme and decoded path of each end.
pub(crate) fn key(e: &crate::finstructable::EdgeEnd) -> String {
    format!(
        "{}:{}{}",
        e.scheme.as_deref().unwrap_or(""),
        if e.absolute { "/" } else { "" },
        e.path()
    )
}

fn directed(e: &Edge) -> bool {
    use crate::finstructable::Flag;
    e.flags
        .iter()
        .any(|f| matches!(f, Flag::DirectionToDestination | Flag::DirectionToSource))
}

impl<'a> Facts<'a> {
    pub fn new(ctx: &'a Context<'a>) -> Self {
        let owner = resolve::owner(ctx.doc, ctx.path, ctx.catalogue, ctx.checkout);
        let scope = Scope {
            doc: ctx.doc,
            owner,
            catalogue: ctx.catalogue,
            checkout: ctx.checkout,
        };
        let ends = ctx
            .doc
            .edges
            .iter()
            .map(|e| (scope.resolve(&e.src), scope.resolve(&e.dest)))
            .collect();
        let mut seen: HashMap<(String, String), usize> = HashMap::new();
        let mut duplicate_of = HashMap::new();
        for (i, e) in ctx.doc.edges.iter().enumerate() {
            let (s, d) = (key(&e.src), key(&e.dest));
            if let Some(&j) = seen.get(&(s.clone(), d.clone())) {
                duplicate_of.insert(i, (j, false));
                continue;
            }
            // FINROC re-orients an edge written against the data flow (no direction flag),
            // so a reversed edge connects the same two ports.
            if let Some(&j) = seen.get(&(d.clone(), s.clone())) {
                if !directed(e) && !directed(&ctx.doc.edges[j]) {
                    duplicate_of.insert(i, (j, true));
                    continue;
                }
            }
            seen.insert((s, d), i);
        }
        Facts {
            scope,
            ends,
            duplicate_of,
        }
    }
}

/// Runs the checks of an application or group file. `not_checked` collects what could
/// not be judged, one sentence each.
pub fn check_structure(ctx: &Context<'_>, out: &mut Diagnostics, not_checked: &mut Vec<String>) {
    let facts = Facts::new(ctx);
    f102_edge_end_missing::check(ctx, &facts, out);
    f103_duplicate_edge::check(ctx, &facts, out);
    f104_sensor_controller_mix::check(ctx, &facts, out);
    f105_group_output_unwritten::check(ctx, &facts, out);
    f108_config_link_missing::check(ctx, out, not_checked);
    f109_dependency_missing::check(ctx, out);
    f110_unknown_component_type::check(ctx, out);
    f111_edge_type_mismatch::check(ctx, &facts, out);
    f112_library_not_built::check(ctx, out);
    f113_parameter_link_target_missing::check(ctx, out);
    f114_edge_to_itself::check(ctx, out);
    f106_config_value_unparsable::check_linked_units(ctx, out);
    // What stayed unknown, grouped by reason.
    let mut reasons: BTreeMap<String, usize> = BTreeMap::new();
    for (s, d) in &facts.ends {
        for end in [s, d] {
            if let End::Unknown(why) = end {
                *reasons.entry(why.clone()).or_default() += 1;
            }
        }
    }
    for (why, n) in reasons {
        not_checked.push(format!(
            "{}: {n} edge end(s) not checked: {why}",
            ctx.path.display()
        ));
    }
}

/// Runs the checks of a config file.
pub fn check_config(cfg: &ConfigFile, out: &mut Diagnostics) {
    f106_config_value_unparsable::check(cfg, out);
    f107_lookup_keys_not_monotonic::check(cfg, out);
}

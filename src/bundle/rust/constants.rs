//! The names of a generated `main.rs`'s module constants: readable, unique, and clear
//! of the file's other constants.

use super::super::layout::Part;
use std::collections::{BTreeSet, HashMap};

/// The other constants of a generated `main.rs`: a module constant of one of these
/// names would be defined twice, and the bundle would not compile.
fn reserved(name: &str) -> bool {
    const FIXED: &[&str] = &[
        "PART",
        "PROGRAM",
        "ABOUT",
        "APPLICATION",
        "PARTS",
        "PERIODS",
        "RECORDABLE",
    ];
    // `LINK_n` (links.rs) and `CALL_n` (service calls between parts).
    let numbered = |prefix: &str| {
        name.strip_prefix(prefix)
            .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
    };
    FIXED.contains(&name) || numbered("LINK_") || numbered("CALL_")
}

/// A readable constant name for every module path of the part: the module's name in
/// upper case, with as many enclosing names as it takes to be unique.
pub(super) fn module_constants(part: &Part<'_>) -> HashMap<String, String> {
    let paths: Vec<Vec<&str>> = part
        .modules
        .iter()
        .map(|m| m.path.split('/').collect())
        .collect();
    let mut depth = vec![1usize; paths.len()];
    let name = |i: usize, k: usize| -> String {
        let segs = &paths[i];
        let from = segs.len().saturating_sub(k);
        let n = segs[from..].join("_").to_uppercase();
        if n.chars().all(|c| c == '_') {
            format!("MODULE{n}")
        } else {
            n
        }
    };
    loop {
        let names: Vec<String> = (0..paths.len()).map(|i| name(i, depth[i])).collect();
        let mut grew = false;
        for i in 0..paths.len() {
            let clash = reserved(&names[i])
                || names
                    .iter()
                    .enumerate()
                    .any(|(j, n)| j != i && *n == names[i]);
            if clash && depth[i] < paths[i].len() {
                depth[i] += 1;
                grew = true;
            }
        }
        if !grew {
            let mut out = HashMap::new();
            let mut taken = BTreeSet::new();
            for (i, mut n) in names.into_iter().enumerate() {
                let base = n.clone();
                let mut k = 2;
                while reserved(&n) || !taken.insert(n.clone()) {
                    n = format!("{base}_{k}");
                    k += 1;
                }
                out.insert(part.modules[i].path.clone(), n);
            }
            return out;
        }
    }
}

//! Calls and servers of a ROS 2 service under another type hash (docs/ros2.md "On the
//! wire"). A service's key ends in the RIHS01 hash of its type, so a client whose
//! definition of the service type differs from ours asks on another key: rmw_zenoh's
//! server never hears of the call, and the client waits for ever. Here:
//!
//! - a server also listens on the service's key with any hash and, for a call under
//!   another one, reports it (throttled, naming the service and both hashes) and answers
//!   it with an error reply saying the same. rmw_zenoh's client logs an error reply's
//!   text (`z_reply_is_ok returned False Reason: …`, rmw_client_data.cpp) and keeps
//!   waiting, so a ROS 2 user reads why; zenoh-ros2-sdk's client fails the call with it.
//!   A call under our hash goes to the service alone; this listener lets it be;
//! - a client watches the liveliness tokens of the service's servers (`SS`, with their
//!   hash) and reports one that announces another hash: our calls will time out, and
//!   this says why.

use ferroc_ros2::def::TypeName;
use ferroc_ros2::rmw_zenoh::mangle;
use ferroc_runtime::console;
use zenoh::pubsub::Subscriber;
use zenoh::query::Queryable;
use zenoh::sample::SampleKind;
use zenoh::{Session, Wait};

/// What a call or a server under another hash is told and reported.
fn help(ty: &TypeName, whose: &str) -> String {
    format!(
        "help: the {whose}'s definition of `{ty}` differs from ours, give both sides the same one"
    )
}

/// The last chunk of a concrete key (no wildcard), if it is not `ours`.
fn other_hash<'k>(key: &'k str, ours: &str) -> Option<&'k str> {
    if key.contains(['*', '$']) {
        return None;
    }
    let theirs = key.rsplit('/').next()?;
    (theirs != ours).then_some(theirs)
}

/// A queryable on `key` (the service's, ending in our hash) with any hash in its place,
/// answering calls under another hash with an error reply and reporting them. Complete,
/// as the service's own queryable: rmw_zenoh's clients send their calls only to
/// complete queryables (`Z_QUERY_TARGET_ALL_COMPLETE`).
pub(super) fn other_hash_calls(
    session: &Session,
    key: &str,
    name: &str,
    ty: &TypeName,
) -> Result<Queryable<()>, String> {
    let (prefix, ours) = key
        .rsplit_once('/')
        .ok_or_else(|| format!("the service key `{key}` has no type hash"))?;
    let (ours, name, ty) = (ours.to_string(), name.to_string(), ty.clone());
    let what = format!("cannot offer the ROS 2 service `{name}`");
    session
        .declare_queryable(format!("{prefix}/*"))
        .complete(true)
        .callback(move |query| {
            let Some(theirs) = other_hash(query.key_expr().as_str(), &ours) else {
                return;
            };
            let why = format!(
                "it was sent with another type hash, {theirs} (ours: {ours}); {}",
                help(&ty, "client")
            );
            console::report_as(
                &format!("ROS 2 service `{name}`: hash"),
                &format!("warning: a request to the ROS 2 service `{name}` was refused: {why}"),
            );
            let _ = query
                .reply_err(format!(
                    "the ROS 2 service `{name}` refused the request: {why}"
                ))
                .wait();
        })
        .wait()
        .map_err(|e| format!("{what}: {e}"))
}

/// A subscriber of the liveliness tokens of the servers of the service `name` (type
/// `ty`, our hash `ours`) in `domain`, reporting each that announces another hash.
pub(super) fn other_hash_servers(
    session: &Session,
    domain: u32,
    name: &str,
    ty: &TypeName,
    ours: &str,
) -> Result<Subscriber<()>, String> {
    // @ros2_lv/<domain>/<zid>/<node id>/<id>/SS/<enclave>/<namespace>/<node>/<service>/
    // <type>/<hash>/<qos> (rmw_zenoh's liveliness_utils.cpp; ferroc_ros2::rmw_zenoh).
    let tokens = format!(
        "@ros2_lv/{domain}/*/*/*/SS/*/*/*/{}/{}/*/*",
        mangle(name),
        mangle(&ty.dds_name())
    );
    let (name, ty, ours) = (name.to_string(), ty.clone(), ours.to_string());
    let what = format!("cannot call the ROS 2 service `{name}`");
    session
        .liveliness()
        .declare_subscriber(tokens)
        .history(true)
        .callback(move |sample| {
            if sample.kind() != SampleKind::Put {
                return;
            }
            let key = sample.key_expr().as_str();
            let Some(theirs) = key.rsplit('/').nth(1).filter(|h| *h != ours) else {
                return;
            };
            console::report_as(
                &format!("ROS 2 service `{name}`: server hash"),
                &format!(
                    "warning: a server of the ROS 2 service `{name}` announces another type \
                     hash, {theirs} (ours: {ours}): our calls do not reach it and time out; {}",
                    help(&ty, "server")
                ),
            );
        })
        .wait()
        .map_err(|e| format!("{what}: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_concrete_key_under_another_hash_is_another_hash() {
        let ours = "RIHS01_aa";
        let prefix = "0/switch_bot/set_enabled/std_srvs::srv::dds_::SetBool_";
        assert_eq!(
            other_hash(&format!("{prefix}/RIHS01_bb"), ours),
            Some("RIHS01_bb")
        );
        assert_eq!(other_hash(&format!("{prefix}/{ours}"), ours), None);
        assert_eq!(other_hash(&format!("{prefix}/*"), ours), None);
        assert_eq!(other_hash("0/**", ours), None);
        assert_eq!(other_hash(&format!("{prefix}/RIHS01_$*"), ours), None);
    }
}

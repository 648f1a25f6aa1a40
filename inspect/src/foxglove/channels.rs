//! The channels the bridge offers, found in the element trees of the application's
//! parts: one per port (topic `/MODULE/PATH/PORT`, its `value/…` answers), and per
//! part `/PART/containers`, `/PART/activities` and `/PART/links` (the lists the keys
//! of the same names answer, as `{containers: […]}` and so on). Messages are JSON with
//! a JSON Schema ([`schema`](super::schema)).

use super::schema;
use crate::client::{Answer, Client};
use crate::request::{key, What};
use ferroc_runtime::inspect::view::Tree;
use foxglove::{ChannelBuilder, Context, RawChannel, Schema};
use std::sync::Arc;
use std::time::Duration;

/// One channel and the key its messages come from.
pub struct Feed {
    /// The channel.
    pub channel: Arc<RawChannel>,
    /// The inspection key polled for it.
    pub key: String,
    /// For a part's list: the field the answer is wrapped in.
    pub wrap: Option<&'static str>,
}

impl Feed {
    /// The message for an answer of the feed's key.
    pub fn message(&self, answer: serde_json::Value) -> Vec<u8> {
        let json = match self.wrap {
            Some(field) => serde_json::json!({ field: answer }),
            None => answer,
        };
        serde_json::to_vec(&json).unwrap_or_default()
    }
}

/// What a port channel is made from.
struct PortSpec {
    topic: String,
    key: String,
    ty: String,
    unit: Option<String>,
}

/// The lists every part answers, and the field each is wrapped in.
const LISTS: [(&str, What); 3] = [
    ("containers", What::Containers),
    ("activities", What::Activities),
    ("links", What::Links),
];

/// The channels of `parts` (name and element tree) of `app`, in `context`. One value
/// of each is read first: it gives the schema of types the model does not spell out.
pub fn build(
    client: &Client,
    app: &str,
    parts: &[(String, Tree)],
    context: &Arc<Context>,
) -> Result<Vec<Feed>, String> {
    let mut ports = Vec::new();
    for (part, tree) in parts {
        for m in &tree.modules {
            for p in &m.ports {
                // An input nothing feeds has no value to show.
                if p.dir == "in" && p.from.is_empty() {
                    continue;
                }
                let path = format!("{}/{}", m.path, p.name);
                ports.push(PortSpec {
                    topic: format!("/{path}"),
                    key: key(app, part, &What::Value(path)),
                    ty: p.r#type.clone(),
                    unit: p.unit.clone(),
                });
            }
        }
    }
    let keys: Vec<String> = ports.iter().map(|p| p.key.clone()).collect();
    let samples = client.ask_all(&keys, Duration::from_secs(5));
    let mut feeds = Vec::new();
    for (p, answers) in ports.iter().zip(samples) {
        let sample = first_ok(&answers).map(|v| v["value"].clone());
        let schema = schema::port(&p.ty, sample.as_ref());
        let mut builder = ChannelBuilder::new(p.topic.as_str())
            .message_encoding("json")
            .schema(json_schema(&p.ty, &schema))
            .add_metadata("type", &p.ty)
            .context(context);
        if let Some(unit) = &p.unit {
            builder = builder.add_metadata("unit", unit);
        }
        feeds.push(Feed {
            channel: builder
                .build_raw()
                .map_err(|e| channel_error(&p.topic, e))?,
            key: p.key.clone(),
            wrap: None,
        });
    }
    for (part, _) in parts {
        let keys: Vec<String> = LISTS.iter().map(|(_, w)| key(app, part, w)).collect();
        let samples = client.ask_all(&keys, Duration::from_secs(5));
        for (((field, _), key), answers) in LISTS.iter().zip(keys).zip(samples) {
            let topic = format!("/{part}/{field}");
            let schema = schema::list(field, first_ok(&answers).as_ref());
            let channel = ChannelBuilder::new(topic.as_str())
                .message_encoding("json")
                .schema(json_schema(field, &schema))
                .context(context)
                .build_raw()
                .map_err(|e| channel_error(&topic, e))?;
            feeds.push(Feed {
                channel,
                key,
                wrap: Some(field),
            });
        }
    }
    Ok(feeds)
}

/// The first answer that is not an error.
pub fn first_ok(answers: &[Answer]) -> Option<serde_json::Value> {
    answers.iter().find_map(|a| a.result.as_ref().ok().cloned())
}

fn json_schema(name: &str, schema: &serde_json::Value) -> Schema {
    Schema::new(
        name,
        "jsonschema",
        serde_json::to_vec(schema).unwrap_or_default(),
    )
}

fn channel_error(topic: &str, e: foxglove::FoxgloveError) -> String {
    format!("the channel `{topic}` cannot be made: {e}")
}

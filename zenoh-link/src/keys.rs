//! The key expressions of an application on Zenoh: a public contract (docs/zenoh.md),
//! so that any Zenoh client can see the traffic.
//!
//! | what | key |
//! |---|---|
//! | a link's values | `ferroc/APP/data/PART/MODULE/PATH/PORT` |
//! | a service called across parts | `ferroc/APP/service/PART/MODULE/PATH/SERVICE` |
//! | lockstep: one instant of a part for another (a `get` with `from=SEQ`: the kept ones again) | `ferroc/APP/lockstep/FROM/TO` |
//! | a part is alive (liveliness token) | `ferroc/APP/alive/PART` |
//!
//! Module paths start with their part in ferroc models; a path that does not gets the
//! part put in front, so every data and service key names its part right after the
//! kind.

use ferroc_terminal::engine_error;
use zenoh::key_expr::OwnedKeyExpr;

/// The keys of one application.
#[derive(Clone, Debug)]
pub struct Keys {
    app: String,
}

impl Keys {
    /// The keys of the application `app`; an error if the name cannot be a key chunk.
    pub fn new(app: &str) -> Result<Keys, String> {
        let keys = Keys { app: app.into() };
        keys.key(&["alive", "x"])?;
        Ok(keys)
    }

    /// `ferroc/APP/data/PART/…`: the values of the output `topic` (module path/port)
    /// of the part `part`.
    pub fn data(&self, part: &str, topic: &str) -> Result<OwnedKeyExpr, String> {
        self.key(&["data", &in_part(part, topic)])
    }

    /// `ferroc/APP/data/PART/**`: every value the part `part` sends.
    pub fn data_of(&self, part: &str) -> Result<OwnedKeyExpr, String> {
        self.key(&["data", part, "**"])
    }

    /// `ferroc/APP/service/PART/…`: the service `service` (module path/name).
    pub fn service(&self, part: &str, service: &str) -> Result<OwnedKeyExpr, String> {
        self.key(&["service", &in_part(part, service)])
    }

    /// `ferroc/APP/lockstep/FROM/TO`: the instants of `from` for `to`.
    pub fn lockstep(&self, from: &str, to: &str) -> Result<OwnedKeyExpr, String> {
        self.key(&["lockstep", from, to])
    }

    /// `ferroc/APP/held/PART`: the question of the part `part` to its readers, which
    /// of its shared-memory buffers they still hold (shm/asking.rs); `*` for the
    /// queryable every part answers it with.
    pub fn held(&self, part: &str) -> Result<OwnedKeyExpr, String> {
        self.key(&["held", part])
    }

    /// `ferroc/APP/alive/PART`: the liveliness token of a part.
    pub fn alive(&self, part: &str) -> Result<OwnedKeyExpr, String> {
        self.key(&["alive", part])
    }

    /// `ferroc/APP/alive/*`: the liveliness tokens of every part.
    pub fn alive_all(&self) -> Result<OwnedKeyExpr, String> {
        self.key(&["alive", "*"])
    }

    /// The part a liveliness key names.
    pub fn part_of_alive<'k>(&self, key: &'k str) -> Option<&'k str> {
        let rest = key
            .strip_prefix("ferroc/")?
            .strip_prefix(self.app.as_str())?;
        rest.strip_prefix("/alive/").filter(|p| !p.contains('/'))
    }

    fn key(&self, chunks: &[&str]) -> Result<OwnedKeyExpr, String> {
        let text = format!("ferroc/{}/{}", self.app, chunks.join("/"));
        OwnedKeyExpr::try_from(text.clone()).map_err(|e| {
            format!(
                "`{text}` cannot be a Zenoh key expression: {}",
                engine_error(&e)
            )
        })
    }
}

/// `topic` with the part in front unless it starts with it.
fn in_part(part: &str, topic: &str) -> String {
    match topic.strip_prefix(part) {
        Some(rest) if rest.starts_with('/') => topic.to_owned(),
        _ => format!("{part}/{topic}"),
    }
}

/// The Zenoh encoding of values of the model type `model_type`: postcard, with the type
/// as the schema (`application/postcard;rescue.VictimList`).
pub fn encoding(model_type: &str) -> zenoh::bytes::Encoding {
    zenoh::bytes::Encoding::from(format!("application/postcard;{model_type}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_name_the_application_part_module_path_and_port() {
        let k = Keys::new("rescue_robot").unwrap();
        let d = k.data("robot", "robot/vision/detector/victims").unwrap();
        assert_eq!(
            d.as_str(),
            "ferroc/rescue_robot/data/robot/vision/detector/victims"
        );
        // A path without its part gets it in front; a part that only starts the same
        // way is not the part.
        let d = k.data("robot", "robotics/x/out").unwrap();
        assert_eq!(d.as_str(), "ferroc/rescue_robot/data/robot/robotics/x/out");
        assert!(k.data_of("robot").unwrap().intersects(&d));
        assert!(!k.data_of("station").unwrap().intersects(&d));
        let s = k.service("station", "station/ops/scale/scale").unwrap();
        assert_eq!(
            s.as_str(),
            "ferroc/rescue_robot/service/station/ops/scale/scale"
        );
        let a = k.alive("robot").unwrap();
        assert_eq!(k.part_of_alive(a.as_str()), Some("robot"));
        assert_eq!(k.part_of_alive("ferroc/other/alive/robot"), None);
        assert!(k.alive_all().unwrap().intersects(&a));
    }

    #[test]
    fn names_that_cannot_be_keys_are_refused_with_the_key() {
        for bad in ["a*b", "a$b", "", "a#b", "a?b"] {
            let err = Keys::new(bad).err().unwrap_or_default();
            assert!(
                err.contains("cannot be a Zenoh key expression"),
                "{bad}: {err}"
            );
        }
        let k = Keys::new("app").unwrap();
        assert!(k.data("p", "p//x").is_err(), "an empty chunk");
    }

    #[test]
    fn the_encoding_names_the_value_type() {
        assert_eq!(
            encoding("rescue.VictimList").to_string(),
            "application/postcard;rescue.VictimList"
        );
    }
}

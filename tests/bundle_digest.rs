//! `manifest.json` names the model and every source file by its SHA-256: a fixed model
//! text has a fixed digest, whichever implementation computes it (the hand-written one
//! was replaced by RustCrypto's `sha2`; the digests did not change).

mod common;
use common::{ferroc, tempdir};

/// A model whose bytes this test fixes; its digest was computed with `sha256sum`.
const MODEL: &str = r#"<application name="digest" version="1">
  <use library="ferroc_std"/>
  <part name="p">
    <thread name="t" period="10ms">
      <module name="c" type="ferroc_std.Constant"><param name="value">2</param></module>
      <module name="s" type="ferroc_std.Scale"/>
    </thread>
    <connect from="t/c/value" to="t/s/input"/>
  </part>
</application>
"#;

const MODEL_SHA256: &str = "fd3348b3211618c707341487cec682e655c61773b8bd7a9cd380540cfef2512b";

#[test]
fn the_manifest_holds_the_known_digest_of_the_model() {
    let dir = tempdir("bundle_digest");
    let model = dir.join("digest.xml");
    std::fs::write(&model, MODEL).unwrap();
    let out = dir.join("b");
    let (code, _, err) = ferroc(&[
        "bundle",
        model.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["model"]["sha256"], MODEL_SHA256, "{manifest}");
    // The model is also one of the sources, under the same digest; no other digest of
    // a source is that of the model.
    let sources = manifest["model"]["sources"].as_array().unwrap();
    let model_entries: Vec<_> = (sources.iter())
        .filter(|s| s["sha256"] == MODEL_SHA256)
        .collect();
    assert_eq!(model_entries.len(), 1, "{manifest}");
    assert_eq!(model_entries[0]["file"], "digest.xml", "{manifest}");
}

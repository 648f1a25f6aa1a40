//! Reading an output's latest value without touching the cycle path: a probe input of
//! the output's type is connected for the moment of the read (the connection's initial
//! push hands it the current value), serialised, and disconnected again. While nobody
//! asks, no probe is connected and publishing costs exactly what it did.

use super::view::PortValue;
use ferroc_module::ValueTable;
use ferroc_ports::port::{ConnectOptions, OutputHandle};

/// The latest value of `output` (of the model type `model_type`) in serde form.
pub(super) fn read(
    values: &ValueTable,
    output: &OutputHandle,
    (port, model_type, unit): (String, &str, Option<String>),
) -> Result<PortValue, String> {
    let value_type = values.get(model_type).ok_or_else(|| {
        format!("`{port}` carries `{model_type}`, which this program's value table does not know")
    })?;
    let (probe, handle) = value_type.input("inspect", None);
    output
        .connect(&handle, ConnectOptions::default())
        .map_err(|e| format!("`{port}` cannot be read: {e}"))?;
    // The initial push delivered the current value if the output ever published.
    let published = probe.changed();
    let mut text = Vec::new();
    let json = match value_type.wire() {
        Some(wire) => wire.json(&probe, &mut text),
        None => {
            let mut s = String::new();
            probe.write_json(&mut s);
            text = s.into_bytes();
            Ok(())
        }
    };
    output.disconnect(&handle);
    json.map_err(|e| format!("`{port}`: the value cannot be written as JSON: {e}"))?;
    let value = serde_json::from_slice(&text)
        .unwrap_or_else(|_| serde_json::Value::String(String::from_utf8_lossy(&text).into()));
    Ok(PortValue {
        port,
        r#type: model_type.to_owned(),
        unit,
        published,
        value,
    })
}

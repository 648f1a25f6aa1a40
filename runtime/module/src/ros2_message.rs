//! A value type that its library maps to a ROS 2 message whose fields it does not have
//! one for one (`ferroc_std.Image` as `sensor_msgs/msg/Image`: no `header`, no
//! `is_bigendian`). The library implements [`Ros2Message`] and registers the type with
//! `Registry::register_ros2`; its manifest says `ros2="package/msg/Name"` on the
//! `<type>`, which check R102 accepts instead of matching field by field. Every ROS 2
//! end of such a port (the wire, `--record`'s ROS 2 channel, `ferroc_std.Player`'s
//! replay) then writes and reads the message through the type's own functions, which
//! fill the message's extra fields truthfully and refuse a sample the type cannot
//! represent.

use super::value::PortValue;
use super::value_table::{DynIn, DynOut};
use ferroc_ports::time::Timestamp;
use ferroc_ros2::serde_cdr::Shape;
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::borrow::Borrow;

/// What a sample says beside the value: filled into the message's `header`.
#[derive(Clone, Copy, Debug)]
pub struct Ros2Meta<'a> {
    /// When the value was written: the time of the step that sends it
    /// ([`Timestamp::now`], model time in a lockstep run).
    pub stamp: Timestamp,
    /// The frame the model names for the topic (`frame-id=`), `""` if none.
    pub frame_id: &'a str,
}

/// A value type written and read as a ROS 2 message by functions of its own (see the
/// module's documentation). Its serde form stays what links between parts and
/// recordings of its own use.
pub trait Ros2Message: PortValue + Serialize + DeserializeOwned {
    /// The message type, `package/msg/Name`.
    const MESSAGE: &'static str;

    /// Writes `self` as a CDR sample of `shape` (the message [`Self::MESSAGE`]) into
    /// `buf`, replacing what it held; an error in words for a value the message cannot
    /// carry.
    fn to_cdr(
        &self,
        shape: &Shape<'_>,
        meta: &Ros2Meta<'_>,
        buf: &mut Vec<u8>,
    ) -> Result<(), String>;

    /// Reads a CDR sample of `shape`; an error in words for a sample that does not
    /// decode or that the type cannot represent.
    fn from_cdr(shape: &Shape<'_>, bytes: &[u8]) -> Result<Self, String>;
}

/// `shape` is the whole message `T` maps to, or an error saying what it is instead.
fn whole<T: Ros2Message>(shape: &Shape<'_>) -> Result<(), String> {
    let message = shape.message().to_string();
    if message == T::MESSAGE {
        Ok(())
    } else {
        Err(format!(
            "`{}` is carried as `{}`, not as `{message}`",
            T::model_type(),
            T::MESSAGE
        ))
    }
}

/// `Codec::ros2_encode` of a mapped type.
pub(crate) fn encode<T: Ros2Message>(
    from: &DynIn,
    shape: &Shape<'_>,
    frame_id: &str,
    bytes: &mut Vec<u8>,
) -> Result<(), String> {
    whole::<T>(shape)?;
    let port = from
        .typed::<T>()
        .ok_or_else(|| format!("`{}` does not carry {}", from.name(), T::model_type()))?;
    let value = port.get();
    let meta = Ros2Meta {
        stamp: Timestamp::now(),
        frame_id,
    };
    T::to_cdr(value.borrow(), shape, &meta, bytes)
}

/// `Codec::ros2_decode` of a mapped type.
pub(crate) fn decode<T: Ros2Message>(
    to: &DynOut,
    shape: &Shape<'_>,
    bytes: &[u8],
) -> Result<(), String> {
    whole::<T>(shape)?;
    let value = T::from_cdr(shape, bytes)?;
    let port = to
        .typed::<T>()
        .ok_or_else(|| format!("`{}` does not carry {}", to.name(), T::model_type()))?;
    port.publish(value);
    Ok(())
}

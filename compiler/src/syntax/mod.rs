//! Text to spanned trees: the XML reader and the language's vocabulary.

pub mod validate;
pub mod vocabulary;
pub mod xml;

pub use validate::AllowRegion;
pub use xml::{Attr, Element};

//! Text to spanned trees: the XML reader and the language's vocabulary.

mod name;
pub mod validate;
pub mod vocabulary;
pub mod xml;

pub use name::Name;
pub use validate::AllowRegion;
pub use xml::{Attr, Element};

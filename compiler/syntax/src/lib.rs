//! Text to spanned trees: the XML reader, the language's vocabulary and its validation,
//! with the checks they raise ([`checks`]). Depends only on `ferroc-diagnostics`.

#![forbid(unsafe_code)]

pub mod checks;
pub mod escape;
mod name;
pub mod validate;
pub mod vocabulary;
pub mod xml;

pub use name::Name;
pub use validate::AllowRegion;
pub use xml::{Attr, Element};

//! The model's one error: a text that is not what it should be, by what it
//! should have been. The message says what was expected (`300 is out of
//! range for SINT (-128 to 127)`); callers that report to a person put it in
//! their diagnostic, and `?` turns it into a `String` where one is wanted.

/// A literal, value, address, tag name or structure's members that does not parse.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Invalid {
    #[error("{0}")]
    Literal(String),
    #[error("{0}")]
    Value(String),
    #[error("{0}")]
    Address(String),
    #[error("{0}")]
    TagName(String),
    #[error("{0}")]
    Members(String),
}

impl From<Invalid> for String {
    fn from(e: Invalid) -> String {
        e.to_string()
    }
}

//! Errors for parameters a user can get wrong.

/// Bad atmosphere parameters: names the field and the range it must lie in.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AtmosphereError {
    /// A field is NaN, infinite or outside its allowed range.
    #[error("atmosphere parameter `{field}` = {value} is out of range: must be {allowed}")]
    OutOfRange {
        /// The field's name as written in the settings file.
        field: &'static str,
        /// The value given.
        value: f64,
        /// The allowed range, in words.
        allowed: &'static str,
    },
}

//! The one error type of the crate: every fallible function takes data a user could get wrong.

/// Errors for inputs that cannot be used (wrong sizes, non-finite or out-of-range values).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MathError {
    /// A cube map face does not hold `size * size` texels.
    #[error("cube map face {face} has {got} texels, expected {expected} ({size} x {size})")]
    CubeMapFace {
        /// Face index, in the order +X, -X, +Y, -Y, +Z, -Z.
        face: usize,
        /// Texels given.
        got: usize,
        /// Texels expected.
        expected: usize,
        /// Edge length in texels.
        size: usize,
    },
    /// A white point colour that cannot be adapted to.
    #[error("white colour component {index} is {value}; each component must be finite and > 0")]
    InvalidWhite {
        /// Channel index (0 = R, 1 = G, 2 = B).
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// A scalar argument outside its allowed range.
    #[error("{name} = {value} is outside the allowed range {allowed}")]
    OutOfRange {
        /// Argument name.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// Human-readable allowed range.
        allowed: &'static str,
    },
    /// A matrix that had to be inverted is singular (degenerate primaries, zero white).
    #[error("singular matrix while computing {context}")]
    Singular {
        /// What was being computed.
        context: &'static str,
    },
}

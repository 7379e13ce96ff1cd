//! The exposure's settings moved to [`crate::techniques::exposure::settings`]; this name stays
//! until the placeholder goes.

pub use crate::techniques::exposure::settings::ExposureSettings;

pub mod lights;
pub mod settings;

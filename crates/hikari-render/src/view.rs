//! The camera as the shaders see it (`hikari::view`).

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec4};

use hikari_scene::Camera;

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct View {
    pub view_proj: [[f32; 4]; 4],
    pub inv_view_proj: [[f32; 4]; 4],
    pub position: [f32; 4],
    pub viewport: [f32; 4],
}

impl View {
    pub fn new(camera: &Camera, width: u32, height: u32) -> Self {
        let vp = camera.projection(width as f32 / height as f32) * camera.view();
        Self {
            view_proj: vp.to_cols_array_2d(),
            inv_view_proj: vp.inverse().to_cols_array_2d(),
            position: camera.position.extend(1.0).to_array(),
            viewport: Vec4::new(
                width as f32,
                height as f32,
                1.0 / width as f32,
                1.0 / height as f32,
            )
            .to_array(),
        }
    }

    pub fn view_proj(&self) -> Mat4 {
        Mat4::from_cols_array_2d(&self.view_proj)
    }
}

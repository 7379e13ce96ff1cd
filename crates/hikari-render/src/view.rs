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
    /// Last frame's view-projection, for motion vectors (this frame's on the first frame).
    pub prev_view_proj: [[f32; 4]; 4],
    /// xyz: unit forward; w: near plane distance in metres.
    pub forward_near: [f32; 4],
    /// xy: this frame's sub-pixel jitter in pixels (x right, y down), already in `view_proj`;
    /// zw: unused. `prev_view_proj` has none, so motion vectors are free of it.
    pub jitter: [f32; 4],
}

impl View {
    pub fn new(camera: &Camera, width: u32, height: u32) -> Self {
        Self::with_previous(camera, camera, width, height)
    }

    /// The view of `camera` whose previous frame was seen from `previous`.
    pub fn with_previous(camera: &Camera, previous: &Camera, width: u32, height: u32) -> Self {
        let aspect = width as f32 / height as f32;
        let vp = camera.projection(aspect) * camera.view();
        let prev = previous.projection(aspect) * previous.view();
        Self {
            prev_view_proj: prev.to_cols_array_2d(),
            forward_near: camera.forward().extend(camera.near).to_array(),
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
            jitter: [0.0; 4],
        }
    }

    /// This view drawn into a `width` x `height` image, its projection unchanged (a frame
    /// rendered below the output's size keeps the output's aspect exactly).
    pub fn with_viewport(mut self, width: u32, height: u32) -> Self {
        self.viewport = Vec4::new(
            width as f32,
            height as f32,
            1.0 / width as f32,
            1.0 / height as f32,
        )
        .to_array();
        self
    }

    /// This view with its image shifted by `jitter` pixels (x right, y down): a surface at
    /// pixel position `q` without jitter is drawn at `q + jitter`.
    pub fn jittered(mut self, jitter: [f32; 2]) -> Self {
        let [w, h] = [self.viewport[0], self.viewport[1]];
        let shift = Mat4::from_translation(glam::Vec3::new(
            2.0 * jitter[0] / w,
            -2.0 * jitter[1] / h,
            0.0,
        ));
        let vp = shift * self.view_proj();
        self.view_proj = vp.to_cols_array_2d();
        self.inv_view_proj = vp.inverse().to_cols_array_2d();
        self.jitter = [jitter[0], jitter[1], 0.0, 0.0];
        self
    }

    pub fn view_proj(&self) -> Mat4 {
        Mat4::from_cols_array_2d(&self.view_proj)
    }
}

//! What the GPU reports outside a call's return value: errors wgpu raises after the fact
//! (validation, out of memory, internal) and a lost device. wgpu's default handler panics on
//! the first; a lost device could leave a caller waiting. Both are recorded here, per device,
//! and turned into a [`RenderError`] by [`GpuFaults::check`], which the renderer calls after
//! each frame it submits: a fault ends the frame with an error naming it.

use std::sync::{Arc, Mutex};

use crate::error::RenderError;

/// Errors kept until checked; more are counted, not stored (a broken pass raises one a frame).
const KEPT: usize = 8;

#[derive(Default)]
struct Recorded {
    errors: Vec<Fault>,
    dropped: u64,
    lost: Option<String>,
}

/// One error the device raised.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Fault {
    OutOfMemory(String),
    Validation(String),
    Internal(String),
}

/// The faults of one device, shared by every clone of its context.
#[derive(Clone, Default)]
pub struct GpuFaults {
    recorded: Arc<Mutex<Recorded>>,
}

impl GpuFaults {
    /// Installs the recorder as `device`'s uncaptured-error handler and lost callback.
    pub fn install(device: &wgpu::Device) -> Self {
        let faults = Self::default();
        let errors = faults.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            let fault = match e {
                wgpu::Error::OutOfMemory { source } => Fault::OutOfMemory(source.to_string()),
                wgpu::Error::Validation { description, .. } => Fault::Validation(description),
                wgpu::Error::Internal { description, .. } => Fault::Internal(description),
            };
            errors.record(fault);
        }));
        let lost = faults.clone();
        device.set_device_lost_callback(move |reason, message| {
            let mut r = lost.lock();
            r.lost.get_or_insert(format!("{reason:?}: {message}"));
        });
        faults
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Recorded> {
        self.recorded.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Records `fault` as if the device had raised it: how tests and the fault switches
    /// (`hikari_render`'s fault switch) reach the paths a real fault takes.
    pub fn record(&self, fault: Fault) {
        let mut r = self.lock();
        if r.errors.len() < KEPT {
            r.errors.push(fault);
        } else {
            r.dropped += 1;
        }
    }

    /// Marks the device lost, as its lost callback does.
    pub fn record_lost(&self, why: &str) {
        self.lock().lost.get_or_insert(why.to_string());
    }

    /// Whether the device was lost; it stays lost.
    pub fn lost(&self) -> Option<String> {
        self.lock().lost.clone()
    }

    /// An error for what was recorded since the last check (the errors are taken; a lost
    /// device stays), or `Ok` if nothing was.
    pub fn check(&self, during: &str) -> Result<(), RenderError> {
        let mut r = self.lock();
        if let Some(why) = &r.lost {
            return Err(RenderError::DeviceLost {
                during: during.to_string(),
                reason: why.clone(),
            });
        }
        if r.errors.is_empty() {
            return Ok(());
        }
        let errors = std::mem::take(&mut r.errors);
        let dropped = std::mem::take(&mut r.dropped);
        let more = if errors.len() > 1 || dropped > 0 {
            format!(
                " (and {} more GPU errors)",
                errors.len() as u64 - 1 + dropped
            )
        } else {
            String::new()
        };
        Err(match &errors[0] {
            Fault::OutOfMemory(m) => RenderError::OutOfMemory {
                during: during.to_string(),
                message: format!("{m}{more}"),
            },
            Fault::Validation(m) | Fault::Internal(m) => RenderError::Gpu {
                during: during.to_string(),
                message: format!("{m}{more}"),
            },
        })
    }
}

//! When the probes' round robin may rest. The irradiance and reflection probes relight a share
//! of themselves every frame so that a moving clock reaches each of them in turn; once the
//! light stops changing (a still render, a viewer with the clock paused) and a whole round has
//! run at the unchanged light, every probe already holds it, and relighting more would
//! redraw the same values. On the CPU driver that round robin was half of a still frame's
//! fixed cost. Probes that become resident and relights of everything (a cut, a new bake, a
//! jump of the sun) are not affected.

use crate::settings::Settings;
use crate::techniques::clouds::CloudParams;

/// Everything a probe's relight reads that can change from frame to frame: the clock, the sun
/// or moon, every setting (conservatively: any change resumes the round robin) and the clouds'
/// parameters (their map and the shadow map's place around the camera).
#[derive(Clone, Debug, PartialEq)]
pub struct LightKey {
    clock_s: f64,
    sun: Option<hikari_scene::Sun>,
    settings: Settings,
    clouds: CloudParams,
}

impl LightKey {
    pub fn new(
        cx: &crate::frame_context::FrameContext,
        s: &Settings,
        clouds: &CloudParams,
    ) -> Self {
        Self {
            clock_s: cx.clock_s,
            sun: cx.sun.clone(),
            settings: s.clone(),
            clouds: *clouds,
        }
    }
}

/// One frame's light for the probes: its key, and whether what they are relit from has
/// settled (the cloud map drawn whole with this frame's parameters; for the reflection probes,
/// also the irradiance probes they are lit by).
#[derive(Clone, Copy, Debug)]
pub struct FrameLight<'a> {
    pub key: &'a LightKey,
    pub settled: bool,
}

/// A technique's count of rounds relit at an unchanged, settled light.
#[derive(Clone, Debug, Default)]
pub struct SteadyLight {
    key: Option<LightKey>,
    rounds: u32,
}

impl SteadyLight {
    /// Whether this frame's round robin may rest: the light is `light.key`, settled, and at
    /// least `cycle` frames' shares (a whole round) were relit at it. A new or unsettled
    /// light starts the count over.
    pub fn rests(&mut self, light: FrameLight, cycle: u32) -> bool {
        if !light.settled || self.key.as_ref() != Some(light.key) {
            self.key = light.settled.then(|| light.key.clone());
            self.rounds = 0;
            return false;
        }
        self.rounds >= cycle
    }

    /// Counts this frame's relight: every probe (`all`), or one round robin share.
    pub fn relit(&mut self, all: bool, cycle: u32) {
        if self.key.is_some() {
            self.rounds = if all {
                self.rounds.max(cycle)
            } else {
                self.rounds.saturating_add(1)
            };
        }
    }

    /// Whether every probe holds the settled light (after this frame's relight).
    pub fn done(&self, cycle: u32) -> bool {
        self.key.is_some() && self.rounds >= cycle
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(clock_s: f64) -> LightKey {
        LightKey {
            clock_s,
            sun: None,
            settings: Settings::default(),
            clouds: bytemuck::Zeroable::zeroed(),
        }
    }

    #[test]
    fn the_round_robin_rests_only_after_a_whole_round_at_a_settled_unchanged_light() {
        let (a, b) = (key(0.0), key(1.0));
        fn at(key: &LightKey, settled: bool) -> FrameLight<'_> {
            FrameLight { key, settled }
        }
        let mut s = SteadyLight::default();
        // A light that keeps changing never rests.
        for i in 0..10 {
            let k = key(i as f64);
            assert!(!s.rests(at(&k, true), 3));
            s.relit(false, 3);
        }
        // Three shares of a cycle of three at an unchanged light, then rest.
        let mut s = SteadyLight::default();
        for _ in 0..3 {
            assert!(!s.rests(at(&a, true), 3));
            s.relit(false, 3);
        }
        assert!(s.rests(at(&a, true), 3));
        assert!(s.done(3));
        // A new light, or one not yet settled, starts over.
        assert!(!s.rests(at(&b, true), 3));
        s.relit(false, 3);
        assert!(!s.rests(at(&b, false), 3));
        s.relit(false, 3);
        assert!(!s.done(3));
        // Relighting everything at a settled light is a whole round at once.
        assert!(!s.rests(at(&a, true), 3));
        s.relit(true, 3);
        assert!(s.rests(at(&a, true), 3));
        // ...but not at an unsettled one.
        let mut s = SteadyLight::default();
        assert!(!s.rests(at(&a, false), 3));
        s.relit(true, 3);
        assert!(!s.rests(at(&a, false), 3));
    }
}

//! Throttled BLAS refits, after Metro Exodus: every update of a deforming entity adds to its
//! accumulated priority (more when visible, less when small or distant); each frame the
//! highest-priority few are refit, plus a few picked at random among the rest with non-zero
//! priority so that high-priority objects never starve the others; a vertex budget caps the
//! frame's work.

use crate::rng::SplitMix64;

#[derive(Clone, Copy, Debug)]
pub struct ThrottleSettings {
    /// Refits per frame taken by priority (Metro: 16).
    pub top: usize,
    /// Refits per frame taken at random from the rest with non-zero priority (Metro: 4).
    pub random: usize,
    /// Most vertices refit per frame. A single object larger than the budget is still refit
    /// when it is the frame's first pick, so it cannot stay outdated forever.
    pub vertex_budget: usize,
    /// Weight of an update of an instance that is not visible this frame.
    pub hidden_weight: f32,
    /// Floor of the size term, so that every update leaves a non-zero priority.
    pub min_size_weight: f32,
    pub seed: u64,
}

impl Default for ThrottleSettings {
    fn default() -> Self {
        Self {
            top: 16,
            random: 4,
            vertex_budget: 1 << 20,
            hidden_weight: 0.1,
            min_size_weight: 1e-3,
            seed: 0x4849_4b41_5249,
        }
    }
}

/// What to refit this frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RefitBatch {
    /// Ids, highest priority first, then the random picks.
    pub ids: Vec<usize>,
    /// How many of `ids` came from the random pick.
    pub random_picks: usize,
    pub vertices: usize,
    /// Deforming objects still outdated after this batch is refit.
    pub outdated: usize,
}

pub struct RefitScheduler {
    settings: ThrottleSettings,
    priority: Vec<f32>,
    vertices: Vec<usize>,
    rng: SplitMix64,
}

impl RefitScheduler {
    pub fn new(settings: ThrottleSettings) -> Self {
        Self {
            rng: SplitMix64::new(settings.seed),
            settings,
            priority: Vec::new(),
            vertices: Vec::new(),
        }
    }

    /// Registers a deforming object (usually one BLAS) and returns its id.
    pub fn register(&mut self, vertex_count: usize) -> usize {
        self.priority.push(0.0);
        self.vertices.push(vertex_count);
        self.priority.len() - 1
    }

    pub fn priority(&self, id: usize) -> f32 {
        self.priority[id]
    }

    /// Number of objects whose geometry moved since their last refit.
    pub fn outdated(&self) -> usize {
        self.priority.iter().filter(|&&p| p > 0.0).count()
    }

    /// The object's geometry changed this frame. `radius` is its bounding-sphere radius and
    /// `distance` its distance from the camera, in the same unit.
    pub fn touch(&mut self, id: usize, visible: bool, radius: f32, distance: f32) {
        let s = &self.settings;
        let size = if distance > radius {
            radius / distance
        } else {
            1.0
        };
        let size = if size.is_finite() { size } else { 1.0 };
        let vis = if visible { 1.0 } else { s.hidden_weight };
        self.priority[id] += vis * size.clamp(s.min_size_weight, 1.0);
    }

    /// Chooses this frame's refits and clears their priority (the caller refits them now).
    pub fn select(&mut self) -> RefitBatch {
        let mut order: Vec<usize> = (0..self.priority.len())
            .filter(|&i| self.priority[i] > 0.0)
            .collect();
        order.sort_by(|&a, &b| {
            self.priority[b]
                .total_cmp(&self.priority[a])
                .then(a.cmp(&b))
        });
        let budget = self.settings.vertex_budget;
        let mut batch = RefitBatch::default();
        let mut rest = Vec::new();
        for &i in &order {
            let fits = batch.vertices + self.vertices[i] <= budget || batch.ids.is_empty();
            if batch.ids.len() < self.settings.top && fits {
                batch.ids.push(i);
                batch.vertices += self.vertices[i];
            } else {
                rest.push(i);
            }
        }
        // Random picks from the remaining non-zero set (partial Fisher-Yates).
        let mut n = rest.len();
        while batch.random_picks < self.settings.random && n > 0 {
            let k = self.rng.below(n);
            let i = rest[k];
            rest.swap(k, n - 1);
            n -= 1;
            if batch.vertices + self.vertices[i] <= budget {
                batch.ids.push(i);
                batch.vertices += self.vertices[i];
                batch.random_picks += 1;
            }
        }
        for &i in &batch.ids {
            self.priority[i] = 0.0;
        }
        batch.outdated = self.outdated();
        batch
    }
}

//! The Purkinje shift of Ghost of Tsushima (Patry 2021), following Cao et al. 2008 and
//! Kirk & O'Brien 2011: at low light the rods feed the cone pathways and shift colours toward
//! blue. Each step of the talk is a function here; [`PurkinjeMatrices`] folds them into the two
//! matrices the talk's three-line shader takes.
//!
//! Units: scene colour `c` is linear Rec.709 with luminance `Y = 0.2126 R + 0.7152 G + 0.0722 B`
//! in the renderer's photometric unit (cd/m² for the talk's constants to mean what they say:
//! the receptor responses are normalised so that a white of luminance 1 gives LMSR ≈ 1, see
//! [`lmsr_from_rec709_integrated`]).
//!
//! Magnitude: at low light the gain `g → 1` and the change becomes linear,
//! `Δc ≈ M̂⁻¹ A⁻¹ (K/S) B diag(k/m) M_R · c`, independent of the input's scale; with these
//! normalisations a grey's L, M, S responses grow by roughly 8x, 10x and 27x (rod-dominated,
//! blue). At higher light `g` shrinks as `q^(-1/2)` and the relative change with it. The talk
//! does not state its receptor normalisation, so an engine may want a strength knob on
//! `rgb_from_lms_gain`.

use super::smits::{N, smits_basis};
use super::spectral::{coarse_d65_unit_luminance, coarse_lmsr};
use super::{Mat3Rows, inv3, mul3};

/// Maximal cone sensitivity `m` (L, M, S) from the talk (Cao et al. 2008).
pub const M_MAX: [f64; 3] = [0.63721, 0.39242, 1.6064];
/// Rod input strength `k` (L, M, S), `k_L = k_M` (the talk's constants, after Kirk 2011).
pub const K_ROD: [f64; 3] = [0.2, 0.2, 0.29];
/// Gain-control factor in `g_i = [1 + 0.33 (q_i + k_i q_R) / m_i]^(−1/2)`.
pub const GAIN_FACTOR: f64 = 0.33;
/// Scaling constant `K`.
pub const K_SCALE: f64 = 45.0;
/// Static saturation `S`.
pub const S_SAT: f64 = 10.0;
/// Surround strength of the opponent signal `k_3`.
pub const K3: f64 = 0.6;
/// Ratio of responses for white light `r_w`.
pub const R_W: f64 = 0.139;
/// Relative weight of L cones `p`.
pub const P_L: f64 = 0.6189;

/// Step 1: `M` (4 x 3), Rec.709 RGB → LMSR receptor response:
/// `M_ij = Σ_λ E_i(λ) I(λ) R_j(λ) Δλ` with `E` = Stockman & Sharpe L, M, S and CIE 1951 V'
/// (each peak 1), `I` = D65 scaled so that a unit reflectance has luminance 1, and `R_j` the
/// computed Smits basis ([`super::smits`]), on the 10 nm grid.
pub fn lmsr_from_rec709_integrated() -> [[f64; 3]; 4] {
    let e = coarse_lmsr();
    let d = coarse_d65_unit_luminance();
    let b = smits_basis();
    let mut m = [[0.0; 3]; 4];
    for (i, row) in m.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = (0..N).map(|l| e[l][i] * d[l] * b.rgb[j][l]).sum();
        }
    }
    m
}

/// Step 2: opponent matrix `A`: `o = A q̂` for an LMS colour `q̂` (rows: L−M, S−(L+M), L+M).
pub const OPPONENT: Mat3Rows = [[-1.0, 1.0, 0.0], [-1.0, -1.0, 1.0], [1.0, 1.0, 0.0]];

/// Step 3: the matrix of the rod increment, `Δo = (K/S) B diag(k) diag(m)⁻¹ g q_R`, with
/// `B = [[−(k₃ + r_w), 1 + k₃ r_w, 0], [p k₃, (1 − p) k₃, 1], [p S, (1 − p) S, 0]]`;
/// returns `(K/S) B diag(k) diag(m)⁻¹`.
pub fn rod_increment_matrix() -> Mat3Rows {
    let b = [
        [-(K3 + R_W), 1.0 + K3 * R_W, 0.0],
        [P_L * K3, (1.0 - P_L) * K3, 1.0],
        [P_L * S_SAT, (1.0 - P_L) * S_SAT, 0.0],
    ];
    let mut out = [[0.0; 3]; 3];
    for r in 0..3 {
        for c in 0..3 {
            out[r][c] = K_SCALE / S_SAT * b[r][c] * K_ROD[c] / M_MAX[c];
        }
    }
    out
}

/// Gain control `g` (L, M, S) for an LMSR response `q`. The bracket is clamped at 1 from
/// below (response ≥ 0) so out-of-gamut negative colours give no NaN; the shader twin does
/// the same.
pub fn gain(q: [f64; 4]) -> [f64; 3] {
    std::array::from_fn(|i| {
        (1.0 + GAIN_FACTOR / M_MAX[i] * (q[i] + K_ROD[i] * q[3]).max(0.0)).powf(-0.5)
    })
}

/// The Purkinje shift written step by step as in the talk: `q = M c`, gain `g`, rod increment
/// `Δo`, and `Δc = M̂⁻¹ A⁻¹ Δo` added to `c`. The reference for [`PurkinjeMatrices::apply`].
pub fn purkinje_reference(c: [f64; 3]) -> [f64; 3] {
    let m = lmsr_from_rec709_integrated();
    let q: [f64; 4] = std::array::from_fn(|i| (0..3).map(|j| m[i][j] * c[j]).sum());
    let g = gain(q);
    let d = rod_increment_matrix();
    let delta_o: [f64; 3] =
        std::array::from_fn(|r| (0..3).map(|k| d[r][k] * g[k]).sum::<f64>() * q[3]);
    let m_hat: Mat3Rows = [m[0], m[1], m[2]];
    let back = mul3(
        &inv3(&m_hat).unwrap_or([[0.0; 3]; 3]),
        &inv3(&OPPONENT).unwrap_or([[0.0; 3]; 3]),
    );
    std::array::from_fn(|r| c[r] + (0..3).map(|k| back[r][k] * delta_o[k]).sum::<f64>())
}

/// The two matrices of the talk's shader:
///
/// ```text
/// lmsr = lmsr_from_rgb · rgb          // 4 x 3
/// g    = 1 / sqrt(1 + lmsr.xyz)
/// rgb' = rgb + (rgb_from_lms_gain · g) · lmsr.w
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PurkinjeMatrices {
    /// Rows L, M, S: `(0.33 / m_i) (M_i + k_i M_R)`, so the shader's `1 + lmsr.xyz` is the gain
    /// control's bracket; row R: `M_R`, the rod response.
    pub lmsr_from_rgb: [[f64; 3]; 4],
    /// `M̂⁻¹ A⁻¹ (K/S) B diag(k) diag(m)⁻¹`: gain vector → RGB change per unit rod response.
    pub rgb_from_lms_gain: Mat3Rows,
}

impl PurkinjeMatrices {
    /// Builds both matrices from the integrated `M` and the talk's constants.
    pub fn new() -> Self {
        let m = lmsr_from_rec709_integrated();
        let mut lmsr_from_rgb = m;
        for i in 0..3 {
            for j in 0..3 {
                lmsr_from_rgb[i][j] = GAIN_FACTOR / M_MAX[i] * (m[i][j] + K_ROD[i] * m[3][j]);
            }
        }
        let m_hat: Mat3Rows = [m[0], m[1], m[2]];
        let back = mul3(
            &inv3(&m_hat).unwrap_or([[0.0; 3]; 3]),
            &inv3(&OPPONENT).unwrap_or([[0.0; 3]; 3]),
        );
        Self {
            lmsr_from_rgb,
            rgb_from_lms_gain: mul3(&back, &rod_increment_matrix()),
        }
    }

    /// The shader's computation, in f64.
    pub fn apply(&self, c: [f64; 3]) -> [f64; 3] {
        let l: [f64; 4] =
            std::array::from_fn(|i| (0..3).map(|j| self.lmsr_from_rgb[i][j] * c[j]).sum());
        let g: [f64; 3] = std::array::from_fn(|i| (1.0 + l[i].max(0.0)).powf(-0.5));
        std::array::from_fn(|r| {
            c[r] + (0..3)
                .map(|k| self.rgb_from_lms_gain[r][k] * g[k])
                .sum::<f64>()
                * l[3]
        })
    }
}

impl Default for PurkinjeMatrices {
    fn default() -> Self {
        Self::new()
    }
}

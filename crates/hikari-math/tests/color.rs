//! Colour science against colour-science (PyPI) fixtures from tools/make_math_fixtures.py.
#![allow(clippy::needless_range_loop)]

mod common;
use common::assert_close;
use hikari_math::MathError;
use hikari_math::color::adaptation::{BRADFORD, white_balance_rec709};
use hikari_math::color::primaries::*;
use hikari_math::color::purkinje::{
    PurkinjeMatrices, lmsr_from_rec709_integrated, purkinje_reference,
};
use hikari_math::color::rayleigh::*;
use hikari_math::color::smits::{basis_colours, smits_basis};
use hikari_math::color::spectral::*;
use hikari_math::color::spectral_data as data;
use hikari_math::color::transfer::{srgb_decode, srgb_encode};
use hikari_math::color::{Mat3Rows, mul3v};
use serde_json::Value;

fn fixture(name: &str) -> Value {
    let path = format!("{}/tests/fixtures/{name}", env!("CARGO_MANIFEST_DIR"));
    serde_json::from_str(&std::fs::read_to_string(&path).expect("fixture present"))
        .expect("valid JSON")
}

/// Equality up to float parsing: serde_json's default parser is not always correctly rounded.
fn same(a: f64, b: f64, what: &str) {
    assert_close(a, b, 1e-14 * a.abs().max(b.abs()), what);
}

fn f(v: &Value) -> f64 {
    v.as_f64().expect("number")
}

fn rows<const R: usize>(v: &Value) -> [[f64; 3]; R] {
    std::array::from_fn(|r| std::array::from_fn(|c| f(&v[r][c])))
}

fn assert_mat<const R: usize>(a: &[[f64; 3]; R], b: &[[f64; 3]; R], tol: f64, what: &str) {
    for r in 0..R {
        for c in 0..3 {
            assert_close(a[r][c], b[r][c], tol, &format!("{what}[{r}][{c}]"));
        }
    }
}

#[test]
fn rgb_xyz_matrices_match_colour_science() {
    let fx = fixture("color_matrices.json");
    let spaces = [
        ("rec709", REC709),
        ("acescg", ACESCG),
        ("aces2065_1", ACES2065_1),
        ("rec2020", REC2020),
        ("display_p3", DISPLAY_P3),
        ("tonemap", TONEMAP),
        ("lms_rayleigh", LMS_RAYLEIGH),
    ];
    for (name, space) in spaces {
        let s = &fx["spaces"][name];
        // The primaries typed in here must be the ones colour-science uses.
        for p in 0..3 {
            for k in 0..2 {
                assert_close(space.primaries[p][k], f(&s["primaries"][p][k]), 1e-12, name);
            }
        }
        assert_mat(&space.rgb_to_xyz(), &rows(&s["rgb_to_xyz"]), 1e-9, name);
        assert_mat(&space.xyz_to_rgb(), &rows(&s["xyz_to_rgb"]), 1e-8, name);
    }
    assert_mat(
        &rgb_to_rgb(&REC709, &TONEMAP),
        &rows(&fx["rec709_to_tonemap_bradford"]),
        1e-9,
        "709->tonemap",
    );
    assert_mat(
        &rgb_to_rgb(&TONEMAP, &REC709),
        &rows(&fx["tonemap_to_rec709_bradford"]),
        1e-9,
        "tonemap->709",
    );
    assert_mat(
        &rgb_to_rgb(&REC709, &ACESCG),
        &rows(&fx["rec709_to_acescg_bradford"]),
        1e-9,
        "709->ACEScg",
    );
    assert_mat(
        &rec709_to_lms_rayleigh(),
        &rows(&fx["rec709_to_lms_rayleigh"]),
        1e-9,
        "709->LMS",
    );
    assert_mat(&BRADFORD, &rows(&fx["bradford"]), 1e-12, "Bradford");
    let degenerate = RgbSpace {
        name: "bad",
        primaries: [[0.3, 0.3]; 3],
        white: D65,
    };
    assert!(degenerate.try_rgb_to_xyz().is_err());
}

#[test]
fn white_balance_matches_colour_science() {
    let fx = fixture("color_matrices.json");
    for case in fx["white_balance"].as_array().unwrap() {
        let t: [f64; 3] = std::array::from_fn(|k| f(&case["target_rec709"][k]));
        let m = white_balance_rec709(t).unwrap();
        assert_mat(
            &m,
            &rows(&case["white_balance_rec709"]),
            1e-9,
            "white balance",
        );
        let w = mul3v(&m, [1.0, 1.0, 1.0]);
        for k in 0..3 {
            assert_close(w[k], t[k], 1e-12, "white maps to the target");
        }
    }
    assert_eq!(
        white_balance_rec709([1.0, 0.0, 1.0]),
        Err(MathError::InvalidWhite {
            index: 1,
            value: 0.0
        })
    );
    assert!(white_balance_rec709([1.0, f64::NAN, 1.0]).is_err());
}

#[test]
fn srgb_transfer_matches_colour_science() {
    let fx = fixture("color_matrices.json");
    for p in fx["srgb_encode"].as_array().unwrap() {
        assert_close(srgb_encode(f(&p[0])), f(&p[1]), 1e-12, "encode");
    }
    // At the 0.04045 knee colour-science picks the power branch, IEC 61966-2-1 the linear one;
    // the two differ by 2e-9 there.
    for p in fx["srgb_decode"].as_array().unwrap() {
        assert_close(srgb_decode(f(&p[0])), f(&p[1]), 1e-8, "decode");
    }
}

#[test]
fn spectral_tables_match_colour_science() {
    let fx = fixture("spectral.json");
    assert_eq!(fx["wavelengths_nm"].as_array().unwrap().len(), data::LEN);
    for i in 0..data::LEN {
        same(wavelength_nm(i), f(&fx["wavelengths_nm"][i]), "grid");
        for k in 0..3 {
            same(data::CIE1931_XYZ[i][k], f(&fx["cie1931_xyz"][i][k]), "CMF");
            same(
                data::STOCKMAN_SHARPE_LMS[i][k],
                f(&fx["stockman_sharpe_lms"][i][k]),
                "LMS",
            );
        }
        same(data::D65[i], f(&fx["d65"][i]), "D65");
        same(data::SCOTOPIC_V[i], f(&fx["scotopic_v"][i]), "V'");
    }
    let names = ["white", "cyan", "magenta", "yellow", "red", "green", "blue"];
    for (row, name) in names.iter().enumerate() {
        for i in 0..10 {
            same(data::SMITS1999[row][i], f(&fx["smits1999"][name][i]), name);
        }
    }
    // D65 table chromaticity from our integration vs colour-science's.
    let w = d65_table_white_xyz();
    let s = w[0] + w[1] + w[2];
    assert_close(w[0] / s, f(&fx["d65_xy_from_tables"][0]), 1e-12, "D65 x");
    assert_close(w[1] / s, f(&fx["d65_xy_from_tables"][1]), 1e-12, "D65 y");
    // ...and it is within rounding of the standard D65 chromaticity.
    assert_close(w[0] / s, 0.3127, 2e-4, "D65 x vs standard");
}

#[test]
fn smits_basis_is_valid_and_matches_scipy() {
    let b = smits_basis();
    for i in 0..b.wavelengths_nm.len() {
        let s: f64 = (0..3).map(|j| b.rgb[j][i]).sum();
        assert_close(s, 1.0, 1e-9, "sum to one");
        for j in 0..3 {
            assert!((0.0..=1.0).contains(&b.rgb[j][i]));
        }
    }
    let c = basis_colours();
    for j in 0..3 {
        for k in 0..3 {
            assert_close(
                c[j][k],
                if j == k { 1.0 } else { 0.0 },
                1e-7,
                "basis colour",
            );
        }
    }
    // Independent solution of the same QP by scipy SLSQP.
    let fx = fixture("smits_purkinje.json");
    let mut obj = 0.0;
    for j in 0..3 {
        for i in 0..b.wavelengths_nm.len() {
            assert_close(
                b.rgb[j][i],
                f(&fx["smits_basis_rgb"][j][i]),
                2e-3,
                "basis vs scipy",
            );
            if i + 1 < b.wavelengths_nm.len() {
                obj += (b.rgb[j][i + 1] - b.rgb[j][i]).powi(2);
            }
        }
    }
    // Ours must be at least as smooth as scipy's (both are feasible).
    assert!(
        obj <= f(&fx["smits_objective"]) + 1e-6,
        "objective {obj} vs scipy {}",
        f(&fx["smits_objective"])
    );
}

#[test]
fn purkinje_matrices_match_reference_and_fast_path() {
    let fx = fixture("smits_purkinje.json");
    let m = lmsr_from_rec709_integrated();
    assert_mat(&m, &rows::<4>(&fx["lmsr_from_rec709_M"]), 1e-7, "M");
    let pm = PurkinjeMatrices::new();
    assert_mat(
        &pm.lmsr_from_rgb,
        &rows::<4>(&fx["lmsr_from_rec709"]),
        2e-3,
        "lmsr_from_rec709",
    );
    let rel: Mat3Rows = rows(&fx["rgb_from_lms_gain"]);
    for r in 0..3 {
        for c in 0..3 {
            assert_close(
                pm.rgb_from_lms_gain[r][c],
                rel[r][c],
                2e-2 * rel[r][c].abs().max(1.0),
                "rgb_from_lms_gain",
            );
        }
    }
    // Folding the talk's steps into two matrices changes nothing.
    for c in [
        [0.01, 0.02, 0.03],
        [1.0, 1.0, 1.0],
        [0.5, 0.1, 0.0],
        [0.001, 0.001, 0.01],
    ] {
        let a = pm.apply(c);
        let b = purkinje_reference(c);
        for k in 0..3 {
            assert_close(a[k], b[k], 1e-12, "fast vs reference");
        }
    }
}

#[test]
fn rayleigh_constants() {
    // Bruneton's three values follow λ⁻⁴ from the 680 nm one.
    for (b, l) in RAYLEIGH_REC709_BRUNETON.iter().zip(BRUNETON_WAVELENGTHS_NM) {
        assert_close(rayleigh_spectral_per_km(l), *b, 0.005 * b, "λ^-4");
    }
    // The talk's LMS values lie between the Rec.709 red and blue values, ordered L < M < S.
    let l = RAYLEIGH_LMS_PATRY;
    assert!(l[0] < l[1] && l[1] < l[2]);
    // Both spaces share D65: white maps to white.
    let w = mul3v(&rec709_to_lms_rayleigh(), [1.0, 1.0, 1.0]);
    for v in w {
        assert_close(v, 1.0, 1e-12, "white");
    }
}

#[test]
fn derived_constants() {
    use hikari_math::DerivedConstants;
    let fx = fixture("color_matrices.json");
    let c = DerivedConstants::new([1.0, 1.0, 1.0]).unwrap();
    assert_mat(
        &c.rec709_to_xyz,
        &rows(&fx["spaces"]["rec709"]["rgb_to_xyz"]),
        1e-9,
        "rec709_to_xyz",
    );
    assert_mat(
        &c.acescg_to_xyz,
        &rows(&fx["spaces"]["acescg"]["rgb_to_xyz"]),
        1e-9,
        "acescg_to_xyz",
    );
    assert_mat(
        &c.tonemap_to_xyz,
        &rows(&fx["spaces"]["tonemap"]["rgb_to_xyz"]),
        1e-9,
        "tonemap_to_xyz",
    );
    assert_mat(
        &c.lms_rayleigh_to_xyz,
        &rows(&fx["spaces"]["lms_rayleigh"]["rgb_to_xyz"]),
        1e-9,
        "lms",
    );
    assert_mat(
        &c.rec709_to_tonemap,
        &rows(&fx["rec709_to_tonemap_bradford"]),
        1e-9,
        "709->tonemap",
    );
    assert_mat(
        &c.white_balance_rec709,
        &[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        1e-12,
        "no WB",
    );
    assert_eq!(c.smits_basis[0].len(), c.smits_wavelengths_nm.len());
    let wb = &fx["white_balance"][0];
    let t: [f64; 3] = std::array::from_fn(|k| f(&wb["target_rec709"][k]));
    let c = DerivedConstants::new(t).unwrap();
    assert_mat(
        &c.white_balance_rec709,
        &rows(&wb["white_balance_rec709"]),
        1e-9,
        "WB",
    );
    assert!(DerivedConstants::new([-1.0, 1.0, 1.0]).is_err());
}

#[test]
fn smits1999_original_algorithm_uses_the_table() {
    use hikari_math::color::smits::smits1999_rgb_to_spectrum;
    let rows = |k: usize| data::SMITS1999[k];
    assert_eq!(smits1999_rgb_to_spectrum([1.0, 1.0, 1.0]), rows(0));
    assert_eq!(smits1999_rgb_to_spectrum([0.0, 1.0, 1.0]), rows(1));
    assert_eq!(smits1999_rgb_to_spectrum([1.0, 0.0, 1.0]), rows(2));
    assert_eq!(smits1999_rgb_to_spectrum([1.0, 1.0, 0.0]), rows(3));
    assert_eq!(smits1999_rgb_to_spectrum([1.0, 0.0, 0.0]), rows(4));
    assert_eq!(smits1999_rgb_to_spectrum([0.0, 1.0, 0.0]), rows(5));
    assert_eq!(smits1999_rgb_to_spectrum([0.0, 0.0, 1.0]), rows(6));
    // (0.2, 0.5, 0.9): 0.2 white + 0.3 cyan + 0.4 blue.
    let s = smits1999_rgb_to_spectrum([0.2, 0.5, 0.9]);
    for i in 0..10 {
        let e = 0.2 * rows(0)[i] + 0.3 * rows(1)[i] + 0.4 * rows(6)[i];
        assert_close(s[i], e, 1e-12, "mix");
    }
}

#[test]
fn lms_rayleigh_primaries_are_spectral() {
    // The talk chose spectral primaries: each must lie on the spectral locus (polyline through
    // the CIE 1931 chromaticities of the 5 nm table) to the 4 digits the talk prints.
    let fx = fixture("spectral.json");
    let locus: Vec<[f64; 2]> = fx["spectral_locus_xy"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| [f(&p[0]), f(&p[1])])
        .collect();
    for p in LMS_RAYLEIGH.primaries {
        let mut best = f64::INFINITY;
        for w in locus.windows(2) {
            let (a, b) = (w[0], w[1]);
            let ab = [b[0] - a[0], b[1] - a[1]];
            let t = (((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1])
                / (ab[0] * ab[0] + ab[1] * ab[1]))
                .clamp(0.0, 1.0);
            let q = [a[0] + t * ab[0], a[1] + t * ab[1]];
            best = best.min(((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt());
        }
        assert!(
            best < 3e-3,
            "primary {p:?} is {best} from the spectral locus"
        );
    }
}

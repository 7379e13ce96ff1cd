//! 3D LUTs in Adobe's Cube LUT format (Cube LUT Specification 1.0, 2013): read, write and
//! sample. A file holds an optional `TITLE "..."`, `LUT_3D_SIZE N` (2 to 256), optional
//! `DOMAIN_MIN r g b` / `DOMAIN_MAX r g b` (default 0 and 1), `#` comments and blank lines,
//! then N³ lines of three numbers, red changing fastest, then green, then blue.
//!
//! hikari grades sRGB-encoded values, so entries must lie in [0, 1] (a tolerance of 1e-5
//! absorbs tools' decimal rounding; such entries are clamped). 1D LUTs are refused.

use std::path::Path;

/// The largest `LUT_3D_SIZE` the specification allows.
pub const MAX_SIZE: usize = 256;
/// How far an entry may stray outside [0, 1] through decimal rounding.
const RANGE_SLACK: f32 = 1e-5;

/// A problem with a `.cube` file, naming the file and, where there is one, the line.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CubeError {
    #[error("{file}: {message}")]
    Io { file: String, message: String },
    #[error("{file}:{line}: {message}")]
    Line {
        file: String,
        line: usize,
        message: String,
    },
    #[error("{file}: {message}")]
    File { file: String, message: String },
}

/// A 3D LUT: `size`³ RGB entries, red fastest, over the input box `domain_min..domain_max`.
#[derive(Clone, Debug, PartialEq)]
pub struct CubeLut {
    pub title: Option<String>,
    pub size: usize,
    pub domain_min: [f32; 3],
    pub domain_max: [f32; 3],
    /// Entry `(r, g, b)` is at `r + size * (g + size * b)`.
    pub data: Vec<[f32; 3]>,
}

impl CubeLut {
    /// The LUT that changes nothing: entry `(r, g, b)` is `(r, g, b) / (size - 1)`.
    pub fn identity(size: usize) -> Self {
        Self::from_fn(size, |c| c)
    }

    /// The LUT of `f` sampled at the lattice points of [0, 1]³.
    pub fn from_fn(size: usize, f: impl Fn([f32; 3]) -> [f32; 3]) -> Self {
        let size = size.max(2);
        let step = 1.0 / (size - 1) as f32;
        let mut data = Vec::with_capacity(size * size * size);
        for b in 0..size {
            for g in 0..size {
                for r in 0..size {
                    data.push(f([r as f32 * step, g as f32 * step, b as f32 * step]));
                }
            }
        }
        Self {
            title: None,
            size,
            domain_min: [0.0; 3],
            domain_max: [1.0; 3],
            data,
        }
    }

    pub fn at(&self, r: usize, g: usize, b: usize) -> [f32; 3] {
        self.data[r + self.size * (g + self.size * b)]
    }

    /// Trilinear interpolation, as colour tools apply a 3D LUT; inputs outside the domain
    /// are clamped to it.
    pub fn sample(&self, c: [f32; 3]) -> [f32; 3] {
        let n = self.size;
        let mut i0 = [0usize; 3];
        let mut f = [0f32; 3];
        for k in 0..3 {
            let t = (c[k] - self.domain_min[k]) / (self.domain_max[k] - self.domain_min[k]);
            let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) } * (n - 1) as f32;
            let base = (t.floor() as usize).min(n - 2);
            i0[k] = base;
            f[k] = t - base as f32;
        }
        let mut out = [0f32; 3];
        for (corner, w) in (0..8).map(|j| {
            let d = [j & 1, (j >> 1) & 1, (j >> 2) & 1];
            let w = (0..3)
                .map(|k| if d[k] == 1 { f[k] } else { 1.0 - f[k] })
                .product::<f32>();
            (d, w)
        }) {
            let e = self.at(i0[0] + corner[0], i0[1] + corner[1], i0[2] + corner[2]);
            for k in 0..3 {
                out[k] += w * e[k];
            }
        }
        out
    }

    /// Reads a `.cube` file.
    pub fn read(path: &Path) -> Result<Self, CubeError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| CubeError::Io {
            file: file.clone(),
            message: format!("cannot read: {e}"),
        })?;
        Self::parse(&text, &file)
    }

    /// Parses the text of a `.cube` file; `file` names it in errors.
    pub fn parse(text: &str, file: &str) -> Result<Self, CubeError> {
        let line_err = |line: usize, message: String| CubeError::Line {
            file: file.into(),
            line,
            message,
        };
        let mut title = None;
        let mut size: Option<usize> = None;
        let mut domain_min = [0.0f32; 3];
        let mut domain_max = [1.0f32; 3];
        let mut data: Vec<[f32; 3]> = Vec::new();
        let mut last_line = 0;
        for (index, raw) in text.lines().enumerate() {
            let line_no = index + 1;
            last_line = line_no;
            let line = raw.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let (keyword, rest) = line
                .split_once(char::is_whitespace)
                .map_or((line, ""), |(k, r)| (k, r.trim()));
            let first = keyword.as_bytes()[0];
            let is_number = first.is_ascii_digit()
                || matches!(first, b'-' | b'+' | b'.')
                || keyword.parse::<f32>().is_ok();
            if !is_number {
                if !data.is_empty() {
                    return Err(line_err(
                        line_no,
                        format!("keyword `{keyword}` after the table's first entry"),
                    ));
                }
                match keyword {
                    "TITLE" => {
                        let t = rest.trim_matches('"');
                        title = Some(t.to_string());
                    }
                    "LUT_3D_SIZE" => {
                        let n: usize = rest.parse().map_err(|_| {
                            line_err(
                                line_no,
                                format!("LUT_3D_SIZE `{rest}` is not a whole number"),
                            )
                        })?;
                        if !(2..=MAX_SIZE).contains(&n) {
                            return Err(line_err(
                                line_no,
                                format!("LUT_3D_SIZE {n} is outside 2 to {MAX_SIZE}"),
                            ));
                        }
                        size = Some(n);
                    }
                    "LUT_1D_SIZE" => {
                        return Err(line_err(
                            line_no,
                            "a 1D LUT; hikari grades with 3D LUTs (LUT_3D_SIZE)".into(),
                        ));
                    }
                    "DOMAIN_MIN" | "DOMAIN_MAX" => {
                        let v = triple(rest)
                            .map_err(|m| line_err(line_no, format!("{keyword}: {m}")))?;
                        if keyword == "DOMAIN_MIN" {
                            domain_min = v;
                        } else {
                            domain_max = v;
                        }
                    }
                    other => {
                        return Err(line_err(line_no, format!("unknown keyword `{other}`")));
                    }
                }
                continue;
            }
            let Some(n) = size else {
                return Err(line_err(line_no, "a table entry before LUT_3D_SIZE".into()));
            };
            let v = triple(line).map_err(|m| line_err(line_no, m))?;
            if let Some(k) = v
                .iter()
                .position(|x| !(-RANGE_SLACK..=1.0 + RANGE_SLACK).contains(x))
            {
                return Err(line_err(
                    line_no,
                    format!(
                        "entry {} is {}, outside 0 to 1",
                        ["red", "green", "blue"][k],
                        v[k]
                    ),
                ));
            }
            if data.len() == n * n * n {
                return Err(line_err(
                    line_no,
                    format!("more than LUT_3D_SIZE³ = {} entries", n * n * n),
                ));
            }
            data.push(v.map(|x| x.clamp(0.0, 1.0)));
        }
        let Some(size) = size else {
            return Err(CubeError::File {
                file: file.into(),
                message: "no LUT_3D_SIZE line: not a 3D .cube LUT".into(),
            });
        };
        if data.len() != size * size * size {
            return Err(line_err(
                last_line,
                format!(
                    "truncated: {} entries for LUT_3D_SIZE {size}, which needs {}",
                    data.len(),
                    size * size * size
                ),
            ));
        }
        if let Some(k) = (0..3).find(|&k| domain_min[k] >= domain_max[k]) {
            return Err(CubeError::File {
                file: file.into(),
                message: format!(
                    "DOMAIN_MIN {} is not below DOMAIN_MAX {} ({})",
                    domain_min[k],
                    domain_max[k],
                    ["red", "green", "blue"][k]
                ),
            });
        }
        Ok(Self {
            title,
            size,
            domain_min,
            domain_max,
            data,
        })
    }

    /// The `.cube` text of this LUT.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        if let Some(t) = &self.title {
            s.push_str(&format!("TITLE \"{}\"\n", t.replace('"', "'")));
        }
        s.push_str("# written by hikari\n");
        s.push_str(&format!("LUT_3D_SIZE {}\n", self.size));
        let [a, b, c] = self.domain_min;
        s.push_str(&format!("DOMAIN_MIN {a} {b} {c}\n"));
        let [a, b, c] = self.domain_max;
        s.push_str(&format!("DOMAIN_MAX {a} {b} {c}\n"));
        for v in &self.data {
            // Rust's shortest representation that reads back to the same f32.
            s.push_str(&format!("{} {} {}\n", v[0], v[1], v[2]));
        }
        s
    }

    /// Writes the `.cube` file atomically (temporary file beside it, then renamed).
    pub fn write(&self, path: &Path) -> crate::error::Result<()> {
        let text = self.to_text();
        crate::output::write_atomically(path, |tmp| {
            std::fs::write(tmp, &text).map_err(|e| crate::error::RenderError::Output {
                path: path.display().to_string(),
                message: e.to_string(),
            })
        })
    }
}

/// Three finite numbers separated by white space.
fn triple(s: &str) -> Result<[f32; 3], String> {
    let parts: Vec<&str> = s.split_whitespace().collect();
    if parts.len() != 3 {
        return Err(format!(
            "expected three numbers, found {}: `{s}`",
            parts.len()
        ));
    }
    let mut v = [0f32; 3];
    for (k, p) in parts.iter().enumerate() {
        let x: f32 = p.parse().map_err(|_| format!("`{p}` is not a number"))?;
        if !x.is_finite() {
            return Err(format!("`{p}` is not a finite number"));
        }
        v[k] = x;
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_identity_round_trips_through_text_and_samples_to_itself() {
        let lut = CubeLut::identity(5);
        let back = CubeLut::parse(&lut.to_text(), "mem").unwrap();
        assert_eq!(back.size, 5);
        for (a, b) in back.data.iter().zip(&lut.data) {
            for k in 0..3 {
                assert!((a[k] - b[k]).abs() < 1e-6);
            }
        }
        let c = [0.123, 0.77, 0.5];
        let s = back.sample(c);
        for k in 0..3 {
            assert!((s[k] - c[k]).abs() < 1e-5, "{s:?}");
        }
    }

    #[test]
    fn bad_files_name_the_file_and_line() {
        let msg = |t: &str| CubeLut::parse(t, "grade.cube").unwrap_err().to_string();
        let head = "TITLE \"x\"\nLUT_3D_SIZE 2\n";
        let rows = "0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n";
        let m = msg(&format!("{head}{rows}"));
        assert!(
            m.starts_with("grade.cube:9:") && m.contains("truncated"),
            "{m}"
        );
        let m = msg(&format!("{head}{rows}nan 1 1\n"));
        assert!(
            m.starts_with("grade.cube:10:") && m.contains("finite"),
            "{m}"
        );
        let m = msg(&format!("{head}{rows}1 1.5 1\n"));
        assert!(m.contains(":10:") && m.contains("outside 0 to 1"), "{m}");
        let m = msg("LUT_3D_SIZE 1\n");
        assert!(m.contains(":1:") && m.contains("outside 2 to 256"), "{m}");
        let m = msg(&format!("{head}{rows}1 1 1\n0 0 0\n"));
        assert!(m.contains(":11:") && m.contains("more than"), "{m}");
        let m = msg("LUT_1D_SIZE 4\n");
        assert!(m.contains("1D"), "{m}");
        let m = msg("# nothing\n");
        assert!(m.contains("no LUT_3D_SIZE"), "{m}");
        let m = msg(&format!("{head}0 0\n"));
        assert!(m.contains(":3:") && m.contains("three numbers"), "{m}");
    }
}

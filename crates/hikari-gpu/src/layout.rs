//! Rust mirrors of WGSL structs and constants are checked against naga's reflection of the
//! WGSL, field by field and value by value, in a test, so the two never drift. The renderer
//! registers its structs ([`gpu_layout!`]) and shared constants ([`gpu_const!`]); the checks
//! here know nothing of them.

use crate::shader::undecorated;

/// A Rust struct's layout as the layout test compares it with the WGSL struct of that name.
#[derive(Debug)]
pub struct StructLayout {
    /// WGSL struct name (the Rust struct has the same name and field names).
    pub name: &'static str,
    /// Entry shader that declares or imports the struct.
    pub shader: &'static str,
    pub size: usize,
    pub fields: Vec<(&'static str, usize)>,
}

/// `gpu_layout!(Type, "shader/path.wgsl", [field, ...])`.
#[macro_export]
macro_rules! gpu_layout {
    ($t:ty, $shader:literal, [$($f:ident),* $(,)?]) => {
        $crate::layout::StructLayout {
            name: stringify!($t).rsplit("::").next().unwrap_or(stringify!($t)).trim(),
            shader: $shader,
            size: ::std::mem::size_of::<$t>(),
            fields: vec![$((stringify!($f), ::std::mem::offset_of!($t, $f))),*],
        }
    };
}

/// A scalar constant both languages declare under one name.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ConstValue {
    U32(u32),
    I32(i32),
    F32(f32),
}

impl From<u32> for ConstValue {
    fn from(v: u32) -> Self {
        ConstValue::U32(v)
    }
}
impl From<i32> for ConstValue {
    fn from(v: i32) -> Self {
        ConstValue::I32(v)
    }
}
impl From<f32> for ConstValue {
    fn from(v: f32) -> Self {
        ConstValue::F32(v)
    }
}

/// A Rust constant and the WGSL file that declares a constant of the same name, type and value.
#[derive(Debug)]
pub struct SharedConstant {
    pub name: &'static str,
    pub shader: &'static str,
    pub value: ConstValue,
}

/// `gpu_const!(path::TO::CONST, "shader/path.wgsl")`.
#[macro_export]
macro_rules! gpu_const {
    ($c:path, $shader:literal) => {
        $crate::layout::SharedConstant {
            name: stringify!($c)
                .rsplit("::")
                .next()
                .unwrap_or(stringify!($c))
                .trim(),
            shader: $shader,
            value: $crate::layout::ConstValue::from($c),
        }
    };
}

/// What differs between `l` and the WGSL struct of its name in `module`; empty when they agree.
pub fn struct_differences(l: &StructLayout, module: &naga::Module) -> Vec<String> {
    let mut failures = Vec::new();
    let mut layouter = naga::proc::Layouter::default();
    if let Err(e) = layouter.update(module.to_ctx()) {
        return vec![format!("{}: naga cannot lay out the module: {e}", l.shader)];
    }
    let found = module.types.iter().find(|(_, t)| {
        t.name.as_deref().map(undecorated) == Some(l.name)
            && matches!(t.inner, naga::TypeInner::Struct { .. })
    });
    let Some((handle, ty)) = found else {
        return vec![format!("{}: no WGSL struct `{}`", l.shader, l.name)];
    };
    let naga::TypeInner::Struct { members, span } = &ty.inner else {
        unreachable!()
    };
    let wgsl: Vec<(String, usize)> = members
        .iter()
        .map(|m| (m.name.clone().unwrap_or_default(), m.offset as usize))
        .collect();
    let rust: Vec<(String, usize)> = l.fields.iter().map(|(n, o)| (n.to_string(), *o)).collect();
    if wgsl != rust {
        failures.push(format!(
            "{}: fields differ\n  WGSL {wgsl:?}\n  Rust {rust:?}",
            l.name
        ));
    }
    if *span as usize != l.size {
        failures.push(format!(
            "{}: WGSL size {} but Rust size {}",
            l.name, span, l.size
        ));
    }
    // A uniform's size must be a multiple of its alignment for arrays and bindings.
    let align = layouter[handle].alignment.round_up(1) as usize;
    if !l.size.is_multiple_of(align) {
        failures.push(format!(
            "{}: size {} not a multiple of alignment {align}",
            l.name, l.size
        ));
    }
    failures
}

/// The value of the scalar constant `name` that the WGSL file `source` declares at module
/// scope. The file's one-line `const` declarations are evaluated by naga on their own: a
/// composed shader would not do, as naga folds a constant that only constant expressions use
/// into its users and drops it.
pub fn wgsl_constant(source: &str, name: &str) -> Result<ConstValue, String> {
    let declarations: String = source
        .lines()
        .map(str::trim)
        .filter(|l| l.starts_with("const ") && l.ends_with(';'))
        .map(|l| format!("{l}\n"))
        .collect();
    let module = naga::front::wgsl::parse_str(&declarations)
        .map_err(|e| format!("its constants do not evaluate alone: {e}"))?;
    let (_, c) = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some(name))
        .ok_or("no module-scope `const` of that name")?;
    match module.global_expressions[c.init] {
        naga::Expression::Literal(naga::Literal::U32(v)) => Ok(ConstValue::U32(v)),
        naga::Expression::Literal(naga::Literal::I32(v)) => Ok(ConstValue::I32(v)),
        naga::Expression::Literal(naga::Literal::F32(v)) => Ok(ConstValue::F32(v)),
        ref e => Err(format!("not a u32, i32 or f32 scalar: {e:?}")),
    }
}

/// Why `c` disagrees with the WGSL file `source` that declares it; `None` when the WGSL
/// constant has the same type and value.
pub fn constant_difference(c: &SharedConstant, source: &str) -> Option<String> {
    match wgsl_constant(source, c.name) {
        Ok(v) if v == c.value => None,
        Ok(v) => Some(format!(
            "{} ({}): WGSL {v:?} but Rust {:?}",
            c.name, c.shader, c.value
        )),
        Err(e) => Some(format!("{} ({}): {e}", c.name, c.shader)),
    }
}

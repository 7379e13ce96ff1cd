//! The shader system: WGSL files composed from shared modules by import path with naga_oil,
//! validated by naga. The files come from the caller (hikari-render embeds its own).
//!
//! A file that starts with `#define_import_path hikari::name` is a module other shaders import
//! with `#import hikari::name`; any other file is an entry shader that pipelines are made from.

use std::collections::{HashMap, HashSet};

use naga_oil::compose::{
    ComposableModuleDescriptor, Composer, NagaModuleDescriptor, ShaderDefValue, ShaderLanguage,
    ShaderType,
};

use crate::error::{RenderError, Result};

/// One WGSL file: its key (`common/sh.wgsl`, `gbuffer/resolve.wgsl`) and its text.
#[derive(Clone, Debug)]
pub struct ShaderFile {
    pub path: String,
    pub source: String,
    /// `Some("hikari::sh")` for modules, `None` for entry shaders.
    pub import_path: Option<String>,
    pub imports: Vec<String>,
}

impl ShaderFile {
    /// A file under the key `path`, its module name and imports read from its preprocessor
    /// directives.
    pub fn new(path: String, source: String) -> Self {
        let (name, imports, _) = naga_oil::compose::get_preprocessor_data(&source);
        ShaderFile {
            path,
            source,
            import_path: name,
            imports: imports.into_iter().map(|i| i.import).collect(),
        }
    }
}

/// Composes entry shaders into naga modules. Build one per renderer and ask it for modules.
pub struct ShaderLibrary {
    composer: Composer,
    files: HashMap<String, ShaderFile>,
}

impl ShaderLibrary {
    /// Loads the modules among `files`. `capabilities` are the naga capabilities the device
    /// offers (f16, subgroups...), so a shader that needs one fails here with a clear message.
    pub fn new(files: Vec<ShaderFile>, capabilities: naga::valid::Capabilities) -> Result<Self> {
        let mut composer = Composer::default().with_capabilities(capabilities);
        // naga_oil needs a module's imports added before the module itself.
        let modules: Vec<&ShaderFile> = files.iter().filter(|f| f.import_path.is_some()).collect();
        let mut added: HashSet<String> = HashSet::new();
        while added.len() < modules.len() {
            let before = added.len();
            for m in &modules {
                let name = m.import_path.clone().unwrap();
                if added.contains(&name) || !m.imports.iter().all(|i| added.contains(i)) {
                    continue;
                }
                let added_module = composer.add_composable_module(ComposableModuleDescriptor {
                    source: &m.source,
                    file_path: &m.path,
                    language: ShaderLanguage::Wgsl,
                    ..Default::default()
                });
                if let Err(e) = added_module {
                    return Err(RenderError::Shader {
                        path: m.path.clone(),
                        message: e.emit_to_string(&composer),
                    });
                }
                added.insert(name);
            }
            if added.len() == before {
                let stuck: Vec<String> = modules
                    .iter()
                    .filter(|m| !added.contains(m.import_path.as_ref().unwrap()))
                    .map(|m| format!("{} (imports {:?})", m.path, m.imports))
                    .collect();
                return Err(RenderError::Shader {
                    path: stuck.join(", "),
                    message: "import cycle or import of a module that does not exist".into(),
                });
            }
        }
        Ok(Self {
            composer,
            files: files.into_iter().map(|f| (f.path.clone(), f)).collect(),
        })
    }

    /// Paths of all entry shaders (files that are not modules), sorted.
    pub fn entry_shaders(&self) -> Vec<String> {
        let mut v: Vec<String> = self
            .files
            .values()
            .filter(|f| f.import_path.is_none())
            .map(|f| f.path.clone())
            .collect();
        v.sort();
        v
    }

    /// The shared binding sets the entry shader at `path` reaches through its imports, in
    /// group order: the first is `@group(1)`. A shared module that needs bindings declares them
    /// as `@group(#{NAME_GROUP}) @binding(i)`; the set is then called `name` (lower case), and
    /// a pass binds it with `PassBuilder::set`. Each set has a group of its own, so a pass
    /// that imports several shared modules cannot see their bindings collide.
    pub fn binding_sets(&self, path: &str) -> Vec<String> {
        let by_import: HashMap<&str, &ShaderFile> = self
            .files
            .values()
            .filter_map(|f| f.import_path.as_deref().map(|i| (i, f)))
            .collect();
        let mut seen: HashSet<&str> = HashSet::new();
        let mut stack: Vec<&ShaderFile> = self.files.get(path).into_iter().collect();
        let mut sets: Vec<String> = Vec::new();
        while let Some(f) = stack.pop() {
            for token in f.source.split("#{").skip(1) {
                if let Some(name) = token
                    .split('}')
                    .next()
                    .and_then(|d| d.trim().strip_suffix("_GROUP"))
                {
                    sets.push(name.to_lowercase());
                }
            }
            for i in &f.imports {
                if seen.insert(i.as_str())
                    && let Some(m) = by_import.get(i.as_str())
                {
                    stack.push(m);
                }
            }
        }
        sets.sort();
        sets.dedup();
        sets
    }

    /// Composes and validates the entry shader at `path` (its key: `common/sh.wgsl`,
    /// `gbuffer/resolve.wgsl`). The groups of its binding sets are defined here
    /// (`NAME_GROUP`, see [`ShaderLibrary::binding_sets`]).
    pub fn module(&mut self, path: &str, defs: &[(&str, ShaderDefValue)]) -> Result<naga::Module> {
        let sets = self.binding_sets(path);
        let file = self.files.get(path).ok_or_else(|| RenderError::Shader {
            path: path.into(),
            message: "no such shader".into(),
        })?;
        let mut shader_defs: std::collections::HashMap<String, ShaderDefValue> =
            defs.iter().map(|(k, v)| (k.to_string(), *v)).collect();
        for (i, set) in sets.iter().enumerate() {
            shader_defs.insert(
                format!("{}_GROUP", set.to_uppercase()),
                ShaderDefValue::UInt(i as u32 + 1),
            );
        }
        self.composer
            .make_naga_module(NagaModuleDescriptor {
                source: &file.source,
                file_path: &file.path,
                shader_type: ShaderType::Wgsl,
                shader_defs,
                additional_imports: &[],
            })
            .map_err(|e| RenderError::Shader {
                path: path.into(),
                message: e.emit_to_string(&self.composer),
            })
    }
}

/// Validates a composed module as the GPU would, returning its layout information.
pub fn validate(
    path: &str,
    module: &naga::Module,
    capabilities: naga::valid::Capabilities,
) -> Result<naga::valid::ModuleInfo> {
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), capabilities)
        .validate(module)
        .map_err(|e| RenderError::Shader {
            path: path.into(),
            message: e.emit_to_string("").to_string(),
        })
}

/// naga capabilities matching the features a device was given.
pub fn capabilities_for(features: wgpu::Features) -> naga::valid::Capabilities {
    use naga::valid::Capabilities as C;
    // Cube map arrays (the reflection probes) are in every backend wgpu drives natively
    // (Vulkan, Metal, DX12); only WebGL lacks them.
    let mut c = C::CUBE_ARRAY_TEXTURES;
    if features.contains(wgpu::Features::SHADER_F16) {
        c |= C::SHADER_FLOAT16;
    }
    if features.contains(wgpu::Features::SUBGROUP) {
        c |= C::SUBGROUP;
    }
    if features.contains(wgpu::Features::SHADER_INT64) {
        c |= C::SHADER_INT64;
    }
    if features.contains(wgpu::Features::SHADER_INT64_ATOMIC_MIN_MAX) {
        c |= C::SHADER_INT64_ATOMIC_MIN_MAX;
    }
    if features.contains(wgpu::Features::SHADER_INT64_ATOMIC_ALL_OPS) {
        c |= C::SHADER_INT64_ATOMIC_ALL_OPS;
    }
    c
}

/// The shader capabilities every adapter the renderer accepts has
/// ([`crate::context::REQUIRED_FEATURES`]), for validating shaders without a GPU.
pub fn required_capabilities() -> naga::valid::Capabilities {
    capabilities_for(crate::context::REQUIRED_FEATURES)
}

/// The name a struct or function had in its WGSL file, without naga_oil's module decoration.
pub fn undecorated(name: &str) -> &str {
    name.split("X_naga_oil_mod_").next().unwrap_or(name)
}

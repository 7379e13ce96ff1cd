//! Errors for bad input geometry and bad instances.

use thiserror::Error;

#[derive(Debug, Error, Clone, PartialEq)]
pub enum BvhError {
    #[error("mesh '{mesh}' has no triangles")]
    EmptyMesh { mesh: String },

    #[error(
        "mesh '{mesh}': every one of its {total} triangles was skipped \
         ({degenerate} degenerate, {non_finite} with NaN/infinite vertices, {out_of_range} with bad indices)"
    )]
    NoValidTriangles {
        mesh: String,
        total: usize,
        degenerate: usize,
        non_finite: usize,
        out_of_range: usize,
    },

    #[error("mesh '{mesh}', triangle {triangle}: vertex {vertex} is not finite ({value:?})")]
    NonFiniteVertex {
        mesh: String,
        triangle: usize,
        vertex: u32,
        value: [f32; 3],
    },

    #[error(
        "mesh '{mesh}', triangle {triangle}: vertex index {index} is out of range (the mesh has {vertex_count} vertices)"
    )]
    IndexOutOfRange {
        mesh: String,
        triangle: usize,
        index: u32,
        vertex_count: usize,
    },

    #[error("mesh '{mesh}', triangle {triangle}: degenerate (zero area)")]
    DegenerateTriangle { mesh: String, triangle: usize },

    #[error("mesh '{mesh}': has {triangles} triangles; at most {max} are supported per BLAS")]
    TooManyTriangles {
        mesh: String,
        triangles: usize,
        max: usize,
    },

    #[error(
        "refit of mesh '{mesh}': got {got} vertices, the BLAS was built from {expected} (refit keeps the topology)"
    )]
    RefitVertexCount {
        mesh: String,
        expected: usize,
        got: usize,
    },

    #[error(
        "mesh '{mesh}': {flags} opacity flags given for {triangles} triangles (one per triangle expected)"
    )]
    OpacityCount {
        mesh: String,
        flags: usize,
        triangles: usize,
    },

    #[error("TLAS over {selected} instances: at most {max} are supported")]
    TooManyInstances { selected: usize, max: usize },

    #[error("instance {instance}: refers to BLAS {blas}, but only {blas_count} BLAS exist")]
    BadBlasIndex {
        instance: usize,
        blas: u32,
        blas_count: usize,
    },
}

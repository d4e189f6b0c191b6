//! Why a case could not become a scene. Kept apart from the scene code, which is compiled once
//! per precision (see `crate::precision`), so that each error has one type whichever precision
//! failed.

use std::path::PathBuf;

use crate::located_toml::SourceLocation;

#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    #[error("{location}: cannot load mesh: {source}")]
    Mesh {
        location: SourceLocation,
        source: MeshError,
    },
    #[error("{location}: {source}")]
    Transform {
        location: SourceLocation,
        source: TransformError,
    },
    #[error("{file}: {source}")]
    CubeMap { file: PathBuf, source: CubeMapError },
}

#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    #[error("the mesh has no triangles")]
    NoTriangles,
    #[error("{count} triangles or vertices are more than a mesh can hold (at most {limit})")]
    TooLarge { count: usize, limit: usize },
    #[error("vertex {vertex} has a non-finite coordinate: {position:?}")]
    NonFinitePosition { vertex: usize, position: [f64; 3] },
    #[error("triangle {triangle} uses vertex {index}, but there are only {vertex_count} vertices")]
    VertexIndexOutOfRange {
        triangle: usize,
        index: u32,
        vertex_count: usize,
    },
    #[error("{found} triangles of normal indices were given for {expected} triangles")]
    NormalTriangleCount { expected: usize, found: usize },
    #[error("triangle {triangle} uses normal {index}, but there are only {normal_count} normals")]
    NormalIndexOutOfRange {
        triangle: usize,
        index: u32,
        normal_count: usize,
    },
    #[error("cannot read {}: {source}", path.display())]
    Read { path: PathBuf, source: std::io::Error },
    #[error("{}:{line}: {problem}", path.display())]
    Malformed {
        path: PathBuf,
        line: usize,
        problem: String,
    },
    #[error("{}: the file has no faces", path.display())]
    NoFaces { path: PathBuf },
    #[error("{}: the OBJ reader failed: {source}", path.display())]
    Obj { path: PathBuf, source: tobj::LoadError },
    #[error("{}: {source}", path.display())]
    InFile { path: PathBuf, source: Box<MeshError> },
}

/// Why a transform cannot be used.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum TransformError {
    #[error("the transform is singular (it flattens space, e.g. a zero scale), so it has no inverse")]
    Singular,
    #[error("the transform is not affine (its bottom row is not 0 0 0 1)")]
    NotAffine,
    #[error("the transform has a non-finite entry")]
    NotFinite,
}

#[derive(Debug, thiserror::Error)]
#[error("cannot load cube map face {path}: {reason}")]
pub struct CubeMapError {
    pub path: PathBuf,
    pub reason: String,
}

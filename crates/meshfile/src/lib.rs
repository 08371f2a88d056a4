//! `meshfile`: triangle meshes read from STL (binary and ASCII), 3MF (the core specification's
//! mesh objects and build items, its `unit` honoured) and Wavefront OBJ, in millimetres
//! ([`read`]); their vertices welded ([`weld`]), their edges counted to tell a closed, manifold
//! surface from one that is not ([`edges`]), split into bodies with their voids ([`bodies`]),
//! and measured ([`measure`]).
//!
//! ```no_run
//! let file = meshfile::read("part.stl").expect("readable");
//! for object in &file.objects {
//!     let welded = meshfile::weld::weld(object, 0.0);
//!     let counts = meshfile::edges::count(&welded.object.triangles);
//!     println!("{}: {} open edge(s)", object.name, counts.open);
//! }
//! ```
#![warn(missing_docs)]

pub mod bodies;
pub mod edges;
pub mod measure;
pub mod needles;
pub mod obj;
pub mod stl;
pub mod threemf;
mod tolerance;
pub mod weld;

use std::path::Path;

/// A triangle mesh of one object, in millimetres.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Object {
    /// The object's name in the file (may be empty).
    pub name: String,
    /// Vertex positions, mm.
    pub positions: Vec<[f64; 3]>,
    /// Triangles over [`Object::positions`], counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

/// The formats read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// STL, binary or ASCII (no unit: millimetres).
    Stl,
    /// 3D Manufacturing Format, core specification.
    ThreeMf,
    /// Wavefront OBJ (no unit: millimetres).
    Obj,
}

impl Format {
    /// The format of a file by its extension (any case): `.stl`, `.3mf`, `.obj`.
    pub fn of(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "stl" => Some(Format::Stl),
            "3mf" => Some(Format::ThreeMf),
            "obj" => Some(Format::Obj),
            _ => None,
        }
    }

    /// Its name as reports give it.
    pub fn name(self) -> &'static str {
        match self {
            Format::Stl => "STL",
            Format::ThreeMf => "3MF",
            Format::Obj => "OBJ",
        }
    }
}

/// A mesh file read: its objects in millimetres.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshFile {
    /// The file's format.
    pub format: Format,
    /// The length unit the file was written in, as its name and millimetres per unit.
    pub unit: (String, f64),
    /// Its objects (3MF: one per build item, placed by the item's transform; STL and OBJ: one).
    pub objects: Vec<Object>,
}

/// Why a mesh file could not be read. Each message is one line.
#[derive(Debug, thiserror::Error)]
pub enum MeshReadError {
    /// The file could not be opened or read.
    #[error("cannot read file: {0}")]
    Io(#[from] std::io::Error),
    /// The file is not of its format, or breaks it.
    #[error("not a valid {format} file: {msg}")]
    Syntax {
        /// The format.
        format: &'static str,
        /// What is wrong.
        msg: String,
    },
    /// The file holds no triangle.
    #[error("no triangle in the file")]
    Empty,
}

impl MeshReadError {
    pub(crate) fn syntax(format: Format, msg: impl Into<String>) -> Self {
        MeshReadError::Syntax {
            format: format.name(),
            msg: msg.into(),
        }
    }
}

/// Whether `path` names a mesh file (by its extension: `.stl`, `.3mf`, `.obj`).
pub fn is_mesh(path: &Path) -> bool {
    Format::of(path).is_some()
}

/// Reads a mesh file, its format by its extension (`.stl`, `.3mf`, `.obj`).
pub fn read(path: impl AsRef<Path>) -> Result<MeshFile, MeshReadError> {
    let path = path.as_ref();
    let format = Format::of(path).ok_or_else(|| MeshReadError::Syntax {
        format: "mesh",
        msg: "the extension is none of .stl, .3mf, .obj".into(),
    })?;
    let bytes = std::fs::read(path)?;
    read_bytes(&bytes, format)
}

/// Reads a mesh file's bytes in `format`.
pub fn read_bytes(bytes: &[u8], format: Format) -> Result<MeshFile, MeshReadError> {
    let mm = ("mm".to_string(), 1.0);
    let file = match format {
        Format::Stl => MeshFile {
            format,
            unit: mm,
            objects: vec![stl::read(bytes)?],
        },
        Format::Obj => MeshFile {
            format,
            unit: mm,
            objects: vec![obj::read(bytes)?],
        },
        Format::ThreeMf => threemf::read(bytes)?,
    };
    if file.objects.iter().all(|o| o.triangles.is_empty()) {
        return Err(MeshReadError::Empty);
    }
    Ok(file)
}

/// A mesh object made ready to plan: welded, closed and manifold, in bodies.
#[derive(Debug, Clone, PartialEq)]
pub struct Closed {
    /// The object welded.
    pub object: Object,
    /// Its bodies.
    pub bodies: Vec<Body>,
    /// The open and non-manifold edges before the gaps were closed (welding within the
    /// tolerance); `None` when the mesh was closed and manifold as read (exact corners
    /// joined).
    pub mended: Option<EdgeCounts>,
    /// Vertices moved to close the gaps.
    pub moved: usize,
    /// Needles (triangles with their corners on one line) split away ([`needles`]).
    pub needles: usize,
}

/// Why a mesh object cannot be planned: its edges after welding within the tolerance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NotClosed {
    /// The edges after welding within the tolerance.
    pub counts: EdgeCounts,
    /// The tolerance, mm.
    pub tolerance: f64,
}

impl std::fmt::Display for NotClosed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the mesh is not closed and manifold: {} open edge(s) and {} non-manifold edge(s) \
             after welding vertices within {} mm (the process tolerance); mend it (close its holes, \
             make each edge shared by two triangles)",
            self.counts.open, self.counts.non_manifold, self.tolerance
        )
    }
}

/// `o` welded (exactly equal corners joined; where that leaves edges open or shared by more
/// than two triangles, corners within `tolerance` mm too), its needles split away and told
/// apart into bodies; refused
/// with its edge counts when it is still not closed and manifold.
pub fn close(o: &Object, tolerance: f64) -> Result<Closed, NotClosed> {
    let exact = weld::weld(o, 0.0);
    let before = edges::count(&exact.object.triangles);
    let (welded, mended) = if before.closed_manifold() {
        (exact, None)
    } else {
        let near = weld::weld(o, tolerance);
        let after = edges::count(&near.object.triangles);
        if !after.closed_manifold() {
            return Err(NotClosed {
                counts: after,
                tolerance,
            });
        }
        (near, Some(before))
    };
    let mut object = welded.object;
    let needles = needles::split_needles(&object.positions, &mut object.triangles);
    Ok(Closed {
        bodies: bodies::bodies(&object),
        object,
        mended,
        moved: welded.moved,
        needles,
    })
}

pub use bodies::Body;
pub use edges::EdgeCounts;

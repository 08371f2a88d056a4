//! The writer's state: entity numbering and the maps from our ids to written entities.

use crate::topology::{Brep, CurveId, EdgeId, FaceId, SurfaceId, VertexId};
use std::collections::HashMap;

/// One solid to write.
pub(super) struct Body {
    pub(super) name: String,
    pub(super) outer: Vec<FaceId>,
    pub(super) voids: Vec<Vec<FaceId>>,
}

/// Entity numbering and the maps from our ids to written entities.
pub(super) struct Writer<'a> {
    pub(super) brep: &'a Brep,
    /// Entity `#k` is `entities[k - 1]` (without the `#k = ` and `;`).
    pub(super) entities: Vec<String>,
    pub(super) vertices: HashMap<VertexId, u64>,
    pub(super) edges: HashMap<EdgeId, u64>,
    pub(super) curves: HashMap<CurveId, u64>,
    pub(super) surfaces: HashMap<SurfaceId, u64>,
}

impl<'a> Writer<'a> {
    pub(super) fn new(brep: &'a Brep) -> Self {
        Writer {
            brep,
            entities: vec![],
            vertices: HashMap::new(),
            edges: HashMap::new(),
            curves: HashMap::new(),
            surfaces: HashMap::new(),
        }
    }

    /// A new entity number whose text is set later.
    pub(super) fn reserve(&mut self) -> u64 {
        self.entities.push(String::new());
        self.entities.len() as u64
    }

    pub(super) fn set(&mut self, id: u64, text: String) {
        self.entities[id as usize - 1] = text;
    }

    pub(super) fn add(&mut self, text: String) -> u64 {
        self.entities.push(text);
        self.entities.len() as u64
    }
}

//! 3MF, the core specification: the model part the package's relationships name (by default
//! `3D/3dmodel.model`), its `unit` (micron, millimeter, centimeter, inch, foot, meter), its
//! mesh objects and the objects made of components, and its build items, each an object
//! placed by its `transform` (and its components' transforms). Each build item is one object;
//! items of objects of type `support` or `other` are left out, as the specification says a
//! consumer may.

use crate::{Format, MeshFile, MeshReadError, Object};
use std::collections::HashMap;
use std::io::Read;

/// The relationship type of a 3MF package's model part.
const MODEL_REL: &str = "http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel";

/// A 3MF transform: rows `[m00 m01 m02] [m10 m11 m12] [m20 m21 m22] [m30 m31 m32]`, a point
/// `p` going to `p · M` (row vector; the last row is the translation).
type Transform = [[f64; 3]; 4];

const IDENTITY: Transform = [[1., 0., 0.], [0., 1., 0.], [0., 0., 1.], [0., 0., 0.]];

fn err(msg: impl Into<String>) -> MeshReadError {
    MeshReadError::syntax(Format::ThreeMf, msg)
}

/// Reads a 3MF package's bytes.
pub fn read(bytes: &[u8]) -> Result<MeshFile, MeshReadError> {
    let mut zip = zip::ZipArchive::new(std::io::Cursor::new(bytes))
        .map_err(|e| err(format!("not a zip package: {e}")))?;
    let mut text = |name: &str| -> Option<String> {
        let mut f = zip.by_name(name.trim_start_matches('/')).ok()?;
        let mut s = String::new();
        f.read_to_string(&mut s).ok()?;
        Some(s)
    };
    let model_path = text("_rels/.rels")
        .and_then(|rels| model_target(&rels))
        .unwrap_or_else(|| "3D/3dmodel.model".to_string());
    let xml = text(&model_path).ok_or_else(|| err(format!("no model part {model_path}")))?;
    read_model(&xml)
}

/// The target of the package relationship of type [`MODEL_REL`].
fn model_target(rels: &str) -> Option<String> {
    let doc = roxmltree::Document::parse(rels).ok()?;
    doc.descendants()
        .filter(|n| n.tag_name().name() == "Relationship")
        .find(|n| n.attribute("Type") == Some(MODEL_REL))
        .and_then(|n| n.attribute("Target"))
        .map(str::to_string)
}

/// Millimetres per unit of a 3MF `unit` attribute.
pub fn mm_per_unit(unit: &str) -> Option<f64> {
    Some(match unit {
        "micron" => 0.001,
        "millimeter" => 1.0,
        "centimeter" => 10.0,
        "inch" => 25.4,
        "foot" => 304.8,
        "meter" => 1000.0,
        _ => return None,
    })
}

/// An object resource: its mesh, or its components.
enum Resource {
    Mesh {
        name: String,
        positions: Vec<[f64; 3]>,
        triangles: Vec<[u32; 3]>,
        printed: bool,
    },
    Components {
        name: String,
        parts: Vec<(String, Transform)>,
        printed: bool,
    },
}

/// Reads the model part's XML.
pub fn read_model(xml: &str) -> Result<MeshFile, MeshReadError> {
    let doc = roxmltree::Document::parse(xml).map_err(|e| err(format!("model XML: {e}")))?;
    let model = doc.root_element();
    if model.tag_name().name() != "model" {
        return Err(err("the model part's root is not <model>"));
    }
    let unit = model.attribute("unit").unwrap_or("millimeter");
    let scale = mm_per_unit(unit).ok_or_else(|| err(format!("unknown unit `{unit}`")))?;
    let mut resources: HashMap<String, Resource> = HashMap::new();
    for o in model
        .descendants()
        .filter(|n| n.tag_name().name() == "object")
    {
        let id = o
            .attribute("id")
            .ok_or_else(|| err("an object without id"))?;
        let name = o.attribute("name").unwrap_or("").to_string();
        let printed = matches!(
            o.attribute("type").unwrap_or("model"),
            "model" | "solidsupport"
        );
        let child = |tag: &str| o.children().find(|n| n.tag_name().name() == tag);
        let resource = if let Some(mesh) = child("mesh") {
            let (positions, triangles) = read_mesh(mesh, id)?;
            Resource::Mesh {
                name,
                positions,
                triangles,
                printed,
            }
        } else if let Some(cs) = child("components") {
            let parts = cs
                .children()
                .filter(|n| n.tag_name().name() == "component")
                .map(|c| {
                    let to = c
                        .attribute("objectid")
                        .ok_or_else(|| err(format!("object {id}: a component without objectid")))?;
                    Ok((to.to_string(), transform(c.attribute("transform"))?))
                })
                .collect::<Result<_, MeshReadError>>()?;
            Resource::Components {
                name,
                parts,
                printed,
            }
        } else {
            return Err(err(format!("object {id} has neither mesh nor components")));
        };
        resources.insert(id.to_string(), resource);
    }
    let build = model
        .children()
        .find(|n| n.tag_name().name() == "build")
        .ok_or_else(|| err("no <build>"))?;
    let mut objects = vec![];
    for item in build.children().filter(|n| n.tag_name().name() == "item") {
        let id = item
            .attribute("objectid")
            .ok_or_else(|| err("a build item without objectid"))?;
        let placed = transform(item.attribute("transform"))?;
        let mut o = Object::default();
        if !flatten(&resources, id, &placed, 0, &mut o)? {
            continue;
        }
        for p in &mut o.positions {
            *p = p.map(|x| x * scale);
        }
        objects.push(o);
    }
    Ok(MeshFile {
        format: Format::ThreeMf,
        unit: (unit.to_string(), scale),
        objects,
    })
}

/// Object `id` placed by `t` appended to `out` (its components' meshes, each placed by its
/// own transform then by `t`). `false` when it is not printed (`support`, `other`).
fn flatten(
    resources: &HashMap<String, Resource>,
    id: &str,
    t: &Transform,
    depth: usize,
    out: &mut Object,
) -> Result<bool, MeshReadError> {
    if depth > 32 {
        return Err(err(format!(
            "object {id}: components nested too deep (a cycle?)"
        )));
    }
    match resources.get(id) {
        None => Err(err(format!("no object {id}"))),
        Some(Resource::Mesh {
            name,
            positions,
            triangles,
            printed,
        }) => {
            if !printed {
                return Ok(false);
            }
            if out.name.is_empty() {
                out.name = name.clone();
            }
            let base = out.positions.len() as u32;
            out.positions.extend(positions.iter().map(|p| apply(t, p)));
            out.triangles
                .extend(triangles.iter().map(|tri| tri.map(|i| i + base)));
            Ok(true)
        }
        Some(Resource::Components {
            name,
            parts,
            printed,
        }) => {
            if !printed {
                return Ok(false);
            }
            if out.name.is_empty() {
                out.name = name.clone();
            }
            let mut any = false;
            for (to, own) in parts {
                any |= flatten(resources, to, &compose(own, t), depth + 1, out)?;
            }
            Ok(any)
        }
    }
}

/// Positions and triangles over them.
type Triangles = (Vec<[f64; 3]>, Vec<[u32; 3]>);

fn read_mesh(mesh: roxmltree::Node, id: &str) -> Result<Triangles, MeshReadError> {
    let mut positions = vec![];
    let mut triangles = vec![];
    for n in mesh.descendants() {
        match n.tag_name().name() {
            "vertex" => {
                let mut p = [0.0; 3];
                for (x, a) in p.iter_mut().zip(["x", "y", "z"]) {
                    *x = n
                        .attribute(a)
                        .and_then(|s| s.trim().parse().ok())
                        .ok_or_else(|| {
                            err(format!("object {id}: a vertex without a number {a}"))
                        })?;
                }
                positions.push(p);
            }
            "triangle" => {
                let mut t = [0u32; 3];
                for (i, a) in t.iter_mut().zip(["v1", "v2", "v3"]) {
                    *i = n
                        .attribute(a)
                        .and_then(|s| s.trim().parse().ok())
                        .ok_or_else(|| err(format!("object {id}: a triangle without {a}")))?;
                }
                triangles.push(t);
            }
            _ => {}
        }
    }
    if let Some(bad) = triangles
        .iter()
        .flatten()
        .find(|&&i| i as usize >= positions.len())
    {
        return Err(err(format!(
            "object {id}: a triangle names vertex {bad} of {}",
            positions.len()
        )));
    }
    Ok((positions, triangles))
}

/// A `transform` attribute: twelve numbers (absent: the identity).
fn transform(attr: Option<&str>) -> Result<Transform, MeshReadError> {
    let Some(s) = attr else {
        return Ok(IDENTITY);
    };
    let v: Vec<f64> = s
        .split_whitespace()
        .map(|w| {
            w.parse()
                .map_err(|_| err(format!("transform `{s}`: `{w}` is no number")))
        })
        .collect::<Result<_, _>>()?;
    if v.len() != 12 {
        return Err(err(format!("transform `{s}`: not twelve numbers")));
    }
    Ok([0, 1, 2, 3].map(|r| [v[3 * r], v[3 * r + 1], v[3 * r + 2]]))
}

/// `p · M`.
fn apply(m: &Transform, p: &[f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|c| p[0] * m[0][c] + p[1] * m[1][c] + p[2] * m[2][c] + m[3][c])
}

/// The transform of `first` then `then`.
fn compose(first: &Transform, then: &Transform) -> Transform {
    let mut out = [[0.0; 3]; 4];
    for r in 0..4 {
        let p = first[r];
        for c in 0..3 {
            out[r][c] = p[0] * then[0][c] + p[1] * then[1][c] + p[2] * then[2][c];
        }
        if r == 3 {
            for c in 0..3 {
                out[r][c] += then[3][c];
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const CUBE: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<model unit="inch" xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02">
 <resources>
  <object id="1" type="model"><mesh><vertices>
   <vertex x="0" y="0" z="0"/><vertex x="1" y="0" z="0"/><vertex x="0" y="1" z="0"/>
  </vertices><triangles><triangle v1="0" v2="1" v3="2"/></triangles></mesh></object>
  <object id="2"><components><component objectid="1" transform="1 0 0 0 1 0 0 0 1 1 0 0"/></components></object>
 </resources>
 <build><item objectid="1"/><item objectid="2" transform="1 0 0 0 1 0 0 0 1 0 0 2"/></build>
</model>"#;

    #[test]
    fn units_and_transforms_are_honoured() {
        let f = read_model(CUBE).unwrap();
        assert_eq!(f.objects.len(), 2);
        assert_eq!(f.unit.1, 25.4);
        assert_eq!(f.objects[0].positions[1], [25.4, 0.0, 0.0]);
        // Component moved 1 along x, then the item 2 along z.
        assert_eq!(f.objects[1].positions[1], [50.8, 0.0, 50.8]);
    }
}

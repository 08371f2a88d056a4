//! Wavefront OBJ: its `v` vertices and `f` faces (`v`, `v/vt`, `v//vn`, `v/vt/vn`, negative
//! indices counting back), polygons fanned into triangles. Groups and objects (`g`, `o`) are
//! one mesh: [`crate::bodies`] tells its bodies apart.

use crate::{Format, MeshReadError, Object};

/// Reads an OBJ file's bytes as one object.
pub fn read(bytes: &[u8]) -> Result<Object, MeshReadError> {
    let text = String::from_utf8_lossy(bytes);
    let err =
        |n: usize, msg: &str| MeshReadError::syntax(Format::Obj, format!("line {}: {msg}", n + 1));
    let mut o = Object::default();
    for (n, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let mut p = [0.0; 3];
                for x in &mut p {
                    *x = words
                        .next()
                        .and_then(|w| w.parse().ok())
                        .ok_or_else(|| err(n, "a vertex needs three numbers"))?;
                }
                o.positions.push(p);
            }
            Some("f") => {
                let count = o.positions.len() as i64;
                let corners = words
                    .map(|w| {
                        let i: i64 = w
                            .split('/')
                            .next()
                            .and_then(|s| s.parse().ok())
                            .ok_or_else(|| err(n, "a face corner needs a vertex index"))?;
                        let k = if i < 0 { count + i } else { i - 1 };
                        if (0..count).contains(&k) {
                            Ok(k as u32)
                        } else {
                            Err(err(n, &format!("vertex {i} is not defined before it")))
                        }
                    })
                    .collect::<Result<Vec<u32>, _>>()?;
                if corners.len() < 3 {
                    return Err(err(n, "a face needs three corners"));
                }
                for k in 1..corners.len() - 1 {
                    o.triangles.push([corners[0], corners[k], corners[k + 1]]);
                }
            }
            Some("o") if o.name.is_empty() => o.name = words.collect::<Vec<_>>().join(" "),
            _ => {}
        }
    }
    Ok(o)
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_quad_is_two_triangles_and_negative_indices_count_back() {
        let o = super::read(
            b"o sq\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1/1/1 2/2/2 3/3/3 4/4/4\nf -4 -2 -1\n",
        )
        .unwrap();
        assert_eq!(o.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 2, 3]]);
        assert_eq!(o.name, "sq");
    }
}

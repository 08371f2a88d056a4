//! STL, binary and ASCII. A binary file is one whose length is its header's triangle count
//! times 50 plus 84 bytes (even when its header starts with `solid`, as some writers' do); any
//! other file starting with `solid` is read as ASCII. Each facet's three corners are its own
//! vertices: [`crate::weld`] joins them.

use crate::{Format, MeshReadError, Object};

/// Reads an STL file's bytes as one object.
pub fn read(bytes: &[u8]) -> Result<Object, MeshReadError> {
    if is_binary(bytes) {
        Ok(binary(bytes))
    } else if bytes.trim_ascii_start().starts_with(b"solid") {
        ascii(bytes)
    } else {
        Err(MeshReadError::syntax(
            Format::Stl,
            "neither binary (its length is not 84 + 50 x its triangle count) nor ASCII (it does not start with `solid`)",
        ))
    }
}

fn is_binary(bytes: &[u8]) -> bool {
    bytes.len() >= 84 && {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        n.checked_mul(50).and_then(|b| b.checked_add(84)) == Some(bytes.len())
    }
}

fn binary(bytes: &[u8]) -> Object {
    let n = (bytes.len() - 84) / 50;
    let f = |at: usize| {
        f32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]) as f64
    };
    let mut o = Object {
        name: String::from_utf8_lossy(&bytes[..80])
            .trim_start_matches("solid")
            .trim_matches(|c: char| c == '\0' || c.is_whitespace())
            .to_string(),
        ..Object::default()
    };
    o.positions.reserve(3 * n);
    o.triangles.reserve(n);
    for k in 0..n {
        // Normal (12 bytes), three corners (36), attribute (2).
        let at = 84 + 50 * k + 12;
        for c in 0..3 {
            let p = at + 12 * c;
            o.positions.push([f(p), f(p + 4), f(p + 8)]);
        }
        let i = 3 * k as u32;
        o.triangles.push([i, i + 1, i + 2]);
    }
    o
}

fn ascii(bytes: &[u8]) -> Result<Object, MeshReadError> {
    let text = String::from_utf8_lossy(bytes);
    let err = |msg: String| MeshReadError::syntax(Format::Stl, msg);
    let mut o = Object::default();
    let mut corners = 0usize;
    for (n, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("solid") if o.name.is_empty() => {
                o.name = words.collect::<Vec<_>>().join(" ");
            }
            Some("vertex") => {
                let mut p = [0.0; 3];
                for x in &mut p {
                    *x = words.next().and_then(|w| w.parse().ok()).ok_or_else(|| {
                        err(format!("line {}: a vertex needs three numbers", n + 1))
                    })?;
                }
                o.positions.push(p);
                corners += 1;
            }
            Some("endloop") => {
                if corners != 3 {
                    return Err(err(format!(
                        "line {}: a facet's loop has {corners} vertices, not 3",
                        n + 1
                    )));
                }
                let i = o.positions.len() as u32 - 3;
                o.triangles.push([i, i + 1, i + 2]);
                corners = 0;
            }
            _ => {}
        }
    }
    Ok(o)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ascii_and_binary_read_the_same_facet() {
        let text = b"solid t\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 1 0\n  endloop\n endfacet\nendsolid t\n";
        let a = read(text).unwrap();
        let mut bin = vec![0u8; 80];
        bin.extend(1u32.to_le_bytes());
        for x in [0f32, 0., 1., 0., 0., 0., 1., 0., 0., 0., 1., 0.] {
            bin.extend(x.to_le_bytes());
        }
        bin.extend([0, 0]);
        let b = read(&bin).unwrap();
        assert_eq!(a.positions, b.positions);
        assert_eq!(a.triangles, b.triangles);
        assert_eq!(a.name, "t");
    }
}

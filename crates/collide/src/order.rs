//! Another order for sibling features (features of the same parents, none built on another):
//! their layers printed in turn, the first layer of each, then the second of each, so no
//! sibling stands higher than the layer being printed beside it.

use std::ops::Range;
use toolpath::{MoveKind, PathPoint, ToolPath};

/// The path with the features `siblings` (file-wide ids) interleaved layer by layer: the k-th
/// layer of each sibling, in the order given, before any (k+1)-th. `None` when the siblings'
/// points are not one run of the path (something else is printed between them), when fewer
/// than two of them print, or when a layer does not begin with a travel (its first bead would
/// be laid from another feature's point).
pub fn interleave(path: &ToolPath, siblings: &[usize]) -> Option<ToolPath> {
    let pts = &path.points;
    let inside = |q: &PathPoint| siblings.contains(&(q.feature as usize));
    let start = pts.iter().position(inside)?;
    let end = start + pts[start..].iter().take_while(|q| inside(q)).count();
    if pts[end..].iter().any(inside) {
        return None;
    }
    // Each sibling's layers, as runs of the path.
    let mut layers: Vec<Vec<Range<usize>>> = vec![vec![]; siblings.len()];
    let mut i = start;
    while i < end {
        let q = &pts[i];
        let n = pts[i..end]
            .iter()
            .take_while(|p| p.feature == q.feature && p.layer == q.layer)
            .count();
        if q.kind != MoveKind::Travel {
            return None;
        }
        let k = siblings.iter().position(|&s| s == q.feature as usize)?;
        layers[k].push(i..i + n);
        i += n;
    }
    if layers.iter().filter(|l| !l.is_empty()).count() < 2 {
        return None;
    }
    let most = layers.iter().map(Vec::len).max().unwrap_or(0);
    let mut points = Vec::with_capacity(pts.len());
    points.extend_from_slice(&pts[..start]);
    for k in 0..most {
        for l in &layers {
            if let Some(r) = l.get(k) {
                points.extend_from_slice(&pts[r.clone()]);
            }
        }
    }
    points.extend_from_slice(&pts[end..]);
    Some(ToolPath { points })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pt(feature: usize, layer: usize, kind: MoveKind) -> PathPoint {
        PathPoint {
            feature: feature as u32,
            layer: layer as u32,
            kind,
            p: [feature as f64, 0.0, layer as f64],
            axis: [0.0, 0.0, 1.0],
            e: 0.0,
            thickness: 0.2,
            width: 0.45,
            role: toolpath::Role::Perimeter,
        }
    }

    #[test]
    fn siblings_take_turns_layer_by_layer() {
        let mut points = vec![pt(0, 0, MoveKind::Travel), pt(0, 0, MoveKind::Print)];
        for f in [1, 2] {
            for l in 0..3 {
                points.push(pt(f, l, MoveKind::Travel));
                points.push(pt(f, l, MoveKind::Print));
            }
        }
        let path = ToolPath { points };
        let mixed = interleave(&path, &[1, 2]).unwrap();
        let order: Vec<(u32, u32)> = mixed
            .points
            .iter()
            .step_by(2)
            .map(|q| (q.feature, q.layer))
            .collect();
        assert_eq!(
            order,
            [(0, 0), (1, 0), (2, 0), (1, 1), (2, 1), (1, 2), (2, 2)]
        );
        // Not siblings in one run: refused.
        assert!(interleave(&path, &[0, 2]).is_none());
    }
}

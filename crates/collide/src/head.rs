//! The print head's shape (the machine profile's `[head]` table): a nozzle cone under a body
//! cylinder, both on the tool axis, and how deep a point lies inside it.

use serde::{Deserialize, Serialize};

/// The head, in the tool-axis frame of the nozzle tip: lengths in mm, angles in degrees.
///
/// - the **nozzle** is a cone frustum from the tip (radius `nozzle_tip_radius`) up the tool axis
///   for `nozzle_length`, widening at `nozzle_cone_half_angle_deg`;
/// - the **body** is a cylinder of radius `body_radius` from `nozzle_length` to `body_length`
///   up the tool axis (`body_length` is measured from the tip, as the nozzle's is).
///
/// The built-in profiles use [`Head::default`]: 0.5 mm, 30°, 8 mm, 20 mm and 60 mm.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Head {
    /// Radius of the nozzle's tip (mm).
    pub nozzle_tip_radius: f64,
    /// Half-angle of the nozzle cone (degrees, 0–80).
    pub nozzle_cone_half_angle_deg: f64,
    /// Length of the nozzle cone up the tool axis from the tip (mm).
    pub nozzle_length: f64,
    /// Radius of the body cylinder above the nozzle (mm).
    pub body_radius: f64,
    /// Top of the body cylinder, from the tip up the tool axis (mm); above `nozzle_length`.
    pub body_length: f64,
}

impl Default for Head {
    fn default() -> Self {
        Head {
            nozzle_tip_radius: 0.5,
            nozzle_cone_half_angle_deg: 30.0,
            nozzle_length: 8.0,
            body_radius: 20.0,
            body_length: 60.0,
        }
    }
}

impl Head {
    /// Checks the table: every figure finite, lengths and radii positive and at most 10 m, the
    /// half-angle in [0, 80)°, `body_length` above `nozzle_length`. The error names the key.
    pub fn validate(&self) -> Result<(), (&'static str, String)> {
        for (field, v) in [
            ("head.nozzle_tip_radius", self.nozzle_tip_radius),
            ("head.nozzle_length", self.nozzle_length),
            ("head.body_radius", self.body_radius),
            ("head.body_length", self.body_length),
        ] {
            if !(v.is_finite() && v > 0.0 && v <= 1e4) {
                return Err((
                    field,
                    format!("must be a positive number up to 1e4 mm, got {v}"),
                ));
            }
        }
        let a = self.nozzle_cone_half_angle_deg;
        if !(a.is_finite() && (0.0..80.0).contains(&a)) {
            return Err((
                "head.nozzle_cone_half_angle_deg",
                format!("must be within 0..80 degrees, got {a}"),
            ));
        }
        if self.body_length <= self.nozzle_length {
            return Err((
                "head.body_length",
                format!(
                    "must be above nozzle_length {} (it is measured from the tip), got {}",
                    self.nozzle_length, self.body_length
                ),
            ));
        }
        Ok(())
    }

    /// The head's solids as the distance bounds the queries use.
    pub fn shape(&self) -> HeadShape {
        let a = self.nozzle_cone_half_angle_deg.to_radians();
        HeadShape {
            tip: self.nozzle_tip_radius,
            tan: a.tan(),
            cos: a.cos(),
            nozzle: self.nozzle_length,
            body_radius: self.body_radius,
            body: self.body_length,
        }
    }
}

/// A [`Head`] ready for queries: the cone's tangent and cosine computed once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadShape {
    tip: f64,
    tan: f64,
    cos: f64,
    nozzle: f64,
    body_radius: f64,
    body: f64,
}

impl HeadShape {
    /// A signed distance bound of the point at height `h` up the tool axis from the tip and `r`
    /// from the axis: negative inside the head (minus the depth to the nearest face of the
    /// cone or the body it lies in), positive outside, and never more than the true distance
    /// outside; 1-Lipschitz, so a box of half-diagonal `ρ` about a point of bound `d > ρ` lies
    /// wholly outside. The cone and the body are each an intersection of convex constraints
    /// (the largest constraint distance), the head their union (the smaller).
    pub fn distance(&self, h: f64, r: f64) -> f64 {
        let cone = self.cone_distance(h, r);
        let body = (self.nozzle - h)
            .max(h - self.body)
            .max(r - self.body_radius);
        cone.min(body)
    }

    /// [`HeadShape::distance`] of the nozzle cone alone (1-Lipschitz too).
    pub fn cone_distance(&self, h: f64, r: f64) -> f64 {
        (-h).max(h - self.nozzle)
            .max((r - self.tip - h * self.tan) * self.cos)
    }

    /// Height of the body's bottom (the cone's top) up the tool axis from the tip.
    pub fn body_bottom(&self) -> f64 {
        self.nozzle
    }

    /// Radius of the circles that bound the head across the tool axis, bottom to top, with
    /// their heights: the tip, the cone's top, the body's bottom and top. The head's lowest
    /// point in any direction lies on one of them.
    pub fn rims(&self) -> [(f64, f64); 4] {
        [
            (0.0, self.tip),
            (self.nozzle, self.tip + self.nozzle * self.tan),
            (self.nozzle, self.body_radius),
            (self.body, self.body_radius),
        ]
    }

    /// Distance from the tip to the head's farthest point.
    pub fn reach(&self) -> f64 {
        self.body.hypot(self.body_radius)
    }

    /// Radius of the widest circle across the tool axis that holds the head: no point farther
    /// from the axis is inside it.
    pub fn widest(&self) -> f64 {
        self.body_radius
            .max(self.tip)
            .max(self.tip + self.nozzle * self.tan)
    }

    /// Top of the body, from the tip up the tool axis.
    pub fn top(&self) -> f64 {
        self.body
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inside_and_outside_the_default_head() {
        let s = Head::default().shape();
        // On the axis 1 mm up: inside the cone, by at most the 1 mm to the tip face.
        let a = 30f64.to_radians();
        assert!((s.distance(1.0, 0.0) + (0.5 + a.tan()) * a.cos()).abs() < 1e-12);
        // Beside the tip: outside.
        assert!(s.distance(0.1, 1.0) > 0.0);
        // Below the tip: outside by the height.
        assert!((s.distance(-0.3, 0.0) - 0.3).abs() < 1e-12);
        // In the body, 19 mm out, 30 mm up: 1 mm inside.
        assert!((s.distance(30.0, 19.0) + 1.0).abs() < 1e-12);
        // Above the body.
        assert!(s.distance(61.0, 0.0) >= 1.0 - 1e-12);
        assert!(Head::default().validate().is_ok());
        let bad = Head {
            body_length: 5.0,
            ..Head::default()
        };
        assert_eq!(bad.validate().unwrap_err().0, "head.body_length");
    }
}

//! Marlin G-code for 3-axis printers: every feature's tool axis must be +Z.
//!
//! The program is what Cura-style G-code viewers expect: `;LAYER:<n>` and `;FEATURE:<id>`
//! comments, relative extrusion (`M83`, each `G1`'s `E` is that segment's filament length),
//! fixed-point numbers (X/Y/Z 3 decimals, E 5, F whole mm/min), retraction around travels.

use crate::{MachineKind, MachineProfile, MoveKind, PathPoint, PostError, ToolPath};
use toolpath::fixed;

/// Largest deviation of a tool axis component from +Z (0, 0, 1) that Marlin accepts.
pub const AXIS_TOLERANCE: f64 = 1e-6;

/// Slack (mm) allowed when checking that the path fits the bed.
const FIT_TOLERANCE: f64 = 1e-6;

/// Lift of the nozzle at the end of the program (mm), kept within the bed height.
const END_LIFT: f64 = 10.0;

/// A Marlin program for the path, or an error naming the first feature whose tool axis is not
/// +Z (within [`AXIS_TOLERANCE`]), saying it needs `delta5` or `kuka`.
///
/// The part is placed with [`bed_offset`] (XY bounding-box centre on the bed centre, lowest
/// bead bottom on Z0); the header states the offset (`; offset X.. Y.. Z..`, machine = part +
/// offset). `source` (the STEP file's name) is written in the first comment line.
///
/// Other errors: the profile is not a `marlin` profile or is invalid, a point holds a NaN or
/// infinite number, or the path does not fit the bed (saying by how much per axis).
///
/// Moves: a travel that follows printing is preceded by a retraction (`G1 E-r`), lifts by
/// `z_hop`, goes by `G0` at the hop height, lowers again and un-retracts (`G1 E+r`) before the
/// next print move; a print move is `G1 X Y Z E F`, at `first_layer_speed` for beads resting
/// on the plate and `print_speed` otherwise. A path that starts with a print point first
/// travels to it.
pub fn marlin(path: &ToolPath, m: &MachineProfile, source: &str) -> Result<String, PostError> {
    m.check_for(MachineKind::Marlin)?;
    path.check_finite()?;
    if let Some(q) = path.points.iter().find(|q| !is_plus_z(q.axis)) {
        return Err(PostError::ToolAxis {
            feature: q.feature,
            i: q.axis[0],
            j: q.axis[1],
            k: q.axis[2],
            machine: MachineKind::Marlin,
        });
    }
    let offset = bed_offset(path, m)?;

    let mut w = Writer::new(m);
    w.header(m, source, offset);
    for q in &path.points {
        let t = [q.p[0] + offset[0], q.p[1] + offset[1], q.p[2] + offset[2]];
        w.comments(q);
        match q.kind {
            MoveKind::Travel => w.travel(t),
            MoveKind::Print => {
                if w.at.is_none() {
                    w.travel(t);
                }
                w.print(t, q);
            }
        }
    }
    w.footer();
    Ok(w.out)
}

/// Whether `axis` is +Z within [`AXIS_TOLERANCE`].
fn is_plus_z(axis: [f64; 3]) -> bool {
    axis[0].abs() <= AXIS_TOLERANCE
        && axis[1].abs() <= AXIS_TOLERANCE
        && (axis[2] - 1.0).abs() <= AXIS_TOLERANCE
}

/// The offset (mm, rounded to 0.001) added to part coordinates to get machine coordinates:
/// the XY bounding-box centre of the print points goes to the bed centre (`bed_size / 2`, or
/// X0 Y0 when `bed_origin_centre`), and the lowest bead bottom (`z − thickness` over print
/// points) to Z0. A path without print points is placed by its travel points; an empty path
/// gets the bed centre.
///
/// Errors with [`PostError::DoesNotFit`] when any point (print points with half their bead
/// width and their thickness) lies outside the bed volume, saying by how much per axis.
pub fn bed_offset(path: &ToolPath, m: &MachineProfile) -> Result<[f64; 3], PostError> {
    let half = [m.bed_size[0] / 2.0, m.bed_size[1] / 2.0];
    let centre = if m.bed_origin_centre {
        [0.0, 0.0]
    } else {
        half
    };
    let placed = placed_points(path);
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for q in &placed {
        let bottom = match q.kind {
            MoveKind::Print => q.p[2] - q.thickness.max(0.0),
            MoveKind::Travel => q.p[2],
        };
        for k in 0..2 {
            lo[k] = lo[k].min(q.p[k]);
            hi[k] = hi[k].max(q.p[k]);
        }
        lo[2] = lo[2].min(bottom);
    }
    let offset = if placed.is_empty() {
        [centre[0], centre[1], 0.0]
    } else {
        [
            round3(centre[0] - (lo[0] / 2.0 + hi[0] / 2.0)),
            round3(centre[1] - (lo[1] / 2.0 + hi[1] / 2.0)),
            // Up, never down: the lowest bead must not end below the plate.
            ((-lo[2] - 1e-9) * 1000.0).ceil() / 1000.0,
        ]
    };

    // Extent of everything the nozzle and the beads occupy, in machine coordinates.
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for q in &path.points {
        let (r, bottom) = match q.kind {
            MoveKind::Print => (q.width.max(0.0) / 2.0, q.p[2] - q.thickness.max(0.0)),
            MoveKind::Travel => (0.0, q.p[2]),
        };
        for k in 0..2 {
            lo[k] = lo[k].min(q.p[k] + offset[k] - r);
            hi[k] = hi[k].max(q.p[k] + offset[k] + r);
        }
        lo[2] = lo[2].min(bottom + offset[2]);
        hi[2] = hi[2].max(q.p[2] + offset[2]);
    }
    let bed_lo = [centre[0] - half[0], centre[1] - half[1], 0.0];
    let bed_hi = [centre[0] + half[0], centre[1] + half[1], m.bed_size[2]];
    let mut excess = Vec::new();
    if !path.points.is_empty() {
        for (k, letter) in ["X", "Y", "Z"].iter().enumerate() {
            let over = (bed_lo[k] - lo[k]).max(0.0) + (hi[k] - bed_hi[k]).max(0.0);
            // NaN (from overflowing coordinates) counts as not fitting.
            let fits = over <= FIT_TOLERANCE && offset[k].is_finite();
            if !fits {
                excess.push(format!("{letter} {} mm", fixed(over, 3)));
            }
        }
    }
    if !excess.is_empty() {
        return Err(PostError::DoesNotFit {
            name: m.name.clone(),
            bed: m.bed_size.map(|v| fixed(v, 0)).join("x"),
            excess: excess.join(", "),
        });
    }
    Ok(offset)
}

/// `v` rounded to 0.001, so the offset written in the header is exact.
fn round3(v: f64) -> f64 {
    (v * 1000.0).round() / 1000.0
}

/// `s` with line breaks and other control characters replaced by spaces, for comments.
fn comment_text(s: &str) -> String {
    s.chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect()
}

/// The program being written and the machine state it leaves.
/// The `;LAYER:` and `;FEATURE:` comments of a G-code program: written where the point's
/// layer or feature changes (shared by the Marlin and delta5 posts).
#[derive(Debug, Default)]
pub(crate) struct LayerMarks {
    layer: Option<usize>,
    feature: Option<usize>,
}

impl LayerMarks {
    /// Appends the comment lines `q` starts to `out`.
    pub(crate) fn write(&mut self, q: &PathPoint, out: &mut String) {
        if self.layer != Some(q.layer) {
            self.layer = Some(q.layer);
            out.push_str(&format!(";LAYER:{}\n", q.layer));
        }
        if self.feature != Some(q.feature) {
            self.feature = Some(q.feature);
            out.push_str(&format!(";FEATURE:{}\n", q.feature));
        }
    }
}

struct Writer {
    out: String,
    /// Nozzle position (machine coordinates) the last move ended at, the hop excluded.
    at: Option<[f64; 3]>,
    /// The filament is retracted.
    retracted: bool,
    /// The last move printed.
    printing: bool,
    /// The nozzle is lifted by the z-hop.
    hopped: bool,
    marks: LayerMarks,
    retraction: f64,
    retraction_f: String,
    travel_f: String,
    print_f: String,
    first_layer_f: String,
    z_hop: f64,
    z_max: f64,
}

impl Writer {
    fn new(m: &MachineProfile) -> Writer {
        let f = |speed: f64| fixed(speed * 60.0, 0);
        Writer {
            out: String::new(),
            at: None,
            retracted: false,
            printing: false,
            hopped: false,
            marks: LayerMarks::default(),
            retraction: m.retraction_length,
            retraction_f: f(m.retraction_speed),
            travel_f: f(m.travel_speed),
            print_f: f(m.print_speed),
            first_layer_f: f(m.first_layer_speed),
            z_hop: m.z_hop,
            z_max: m.bed_size[2],
        }
    }

    fn line(&mut self, s: &str) {
        self.out.push_str(s);
        self.out.push('\n');
    }

    fn header(&mut self, m: &MachineProfile, source: &str, offset: [f64; 3]) {
        let t = |v: f64| fixed(v, 0);
        self.line(&format!(
            "; generated by features from {}",
            comment_text(source)
        ));
        self.line(&format!("; machine: {} (marlin)", comment_text(&m.name)));
        self.line(&format!(
            "; offset X{} Y{} Z{} (machine = part + offset)",
            fixed(offset[0], 3),
            fixed(offset[1], 3),
            fixed(offset[2], 3)
        ));
        self.line(&format!(
            "; nozzle {} mm, filament {} mm, bead {} mm",
            fixed(m.nozzle_diameter, 2),
            fixed(m.filament_diameter, 2),
            fixed(m.bead_width, 2)
        ));
        self.line(";FLAVOR:Marlin");
        self.line("G21 ; millimetres");
        self.line("G90 ; absolute XYZ");
        self.line("M83 ; relative extrusion: E is each segment's filament length");
        self.line(&format!("M140 S{} ; bed", t(m.bed_temperature)));
        self.line(&format!("M104 S{} ; nozzle", t(m.nozzle_temperature)));
        self.line("G28 ; home all axes");
        if m.bed_temperature > 0.0 {
            self.line(&format!(
                "M190 S{} ; wait for the bed",
                t(m.bed_temperature)
            ));
        }
        self.line(&format!(
            "M109 S{} ; wait for the nozzle",
            t(m.nozzle_temperature)
        ));
        self.line("G92 E0");
    }

    /// `;LAYER:` and `;FEATURE:` comments where the point's layer or feature changes.
    fn comments(&mut self, q: &PathPoint) {
        self.marks.write(q, &mut self.out);
    }

    fn retract(&mut self) {
        if self.retraction > 0.0 && !self.retracted {
            let line = format!("G1 E-{} F{}", fixed(self.retraction, 5), self.retraction_f);
            self.line(&line);
            self.retracted = true;
        }
    }

    fn hop_z(&self, z: f64) -> f64 {
        (z + self.z_hop).min(self.z_max).max(z)
    }

    fn travel(&mut self, t: [f64; 3]) {
        if self.printing {
            self.retract();
        }
        self.printing = false;
        if self.z_hop > 0.0 && !self.hopped {
            if let Some(at) = self.at {
                let line = format!("G0 Z{} F{}", fixed(self.hop_z(at[2]), 3), self.travel_f);
                self.line(&line);
            }
            self.hopped = true;
        }
        let z = if self.hopped { self.hop_z(t[2]) } else { t[2] };
        let line = format!(
            "G0 X{} Y{} Z{} F{}",
            fixed(t[0], 3),
            fixed(t[1], 3),
            fixed(z, 3),
            self.travel_f
        );
        self.line(&line);
        self.at = Some(t);
    }

    fn print(&mut self, t: [f64; 3], q: &PathPoint) {
        if self.hopped {
            if let Some(at) = self.at {
                let line = format!("G0 Z{} F{}", fixed(at[2], 3), self.travel_f);
                self.line(&line);
            }
            self.hopped = false;
        }
        if self.retracted {
            let line = format!("G1 E{} F{}", fixed(self.retraction, 5), self.retraction_f);
            self.line(&line);
            self.retracted = false;
        }
        // A bead resting on the plate (its bottom within 10 µm of Z0) goes at first-layer speed.
        let on_plate = t[2] - q.thickness.max(0.0) <= 0.01;
        let f = if on_plate {
            &self.first_layer_f
        } else {
            &self.print_f
        };
        let line = format!(
            "G1 X{} Y{} Z{} E{} F{}",
            fixed(t[0], 3),
            fixed(t[1], 3),
            fixed(t[2], 3),
            fixed(q.e, 5),
            f
        );
        self.line(&line);
        self.printing = true;
        self.at = Some(t);
    }

    fn footer(&mut self) {
        self.line("; end");
        self.retract();
        self.line("M104 S0 ; nozzle off");
        self.line("M140 S0 ; bed off");
        if let Some(at) = self.at {
            let z = (at[2].max(0.0) + END_LIFT).min(self.z_max);
            let line = format!("G0 Z{} F{}", fixed(z, 3), self.travel_f);
            self.line(&line);
        }
        self.line("G28 X0 Y0 ; home X and Y");
        self.line("M84 ; motors off");
    }
}

/// The points a post places the part by: the print points, or every point of a path without
/// any (travel only).
pub(crate) fn placed_points(path: &ToolPath) -> Vec<&PathPoint> {
    let prints: Vec<&PathPoint> = path
        .points
        .iter()
        .filter(|q| q.kind == MoveKind::Print)
        .collect();
    if prints.is_empty() {
        path.points.iter().collect()
    } else {
        prints
    }
}

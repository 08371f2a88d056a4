//! Machine profiles: what the machine is (nozzle, filament, bead, speeds, temperatures, bed),
//! read from TOML. The built-in profiles are the commented files in the repository's
//! `profiles/` folder, compiled in with `include_str!`, so a user can copy one and edit it.

pub use crate::kind::MachineKind;
use crate::PostError;
use toolpath::Bead;

/// The bundled `profiles/marlin.toml`: a generic 220x220x250 mm Marlin printer.
pub const MARLIN_TOML: &str = include_str!("../../../profiles/marlin.toml");
/// The bundled `profiles/delta5.toml`: a generic 5-axis printer.
pub const DELTA5_TOML: &str = include_str!("../../../profiles/delta5.toml");
/// The bundled `profiles/kuka.toml`: a generic KUKA robot deposition cell.
pub const KUKA_TOML: &str = include_str!("../../../profiles/kuka.toml");
/// The bundled `profiles/process.toml`: the process file format (`[defaults]` and
/// `[features.<id>]` tables) with its default values, for the planner and for users to copy.
pub const PROCESS_TOML: &str = include_str!("../../../profiles/process.toml");

/// A machine profile. Lengths in mm, speeds in mm/s, temperatures in °C. The TOML form has
/// exactly these keys (unknown keys are refused); see `profiles/marlin.toml` for each key's
/// meaning.
#[derive(Debug, Clone, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct MachineProfile {
    /// Human-readable name, written in program headers.
    pub name: String,
    /// Which post the profile is for.
    pub kind: MachineKind,
    /// Nozzle bore (mm).
    pub nozzle_diameter: f64,
    /// Filament diameter D (mm), for the extrusion of Isa & Lazoglu 2019, Eq. 1.
    pub filament_diameter: f64,
    /// Bead width w (mm).
    pub bead_width: f64,
    /// Narrowest bead the nozzle lays well (mm); narrower beads of a plan are widened to it
    /// (their filament with them) with a warning.
    /// Optional: 0.6 × `nozzle_diameter` when left out ([`MachineProfile::min_bead_width`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_bead_width: Option<f64>,
    /// Filament density (g/cm³) for the filament mass of a plan's estimate. Optional: PLA's
    /// 1.24 when left out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub filament_density: Option<f64>,
    /// Printing speed (mm/s).
    pub print_speed: f64,
    /// Printing speed of beads resting on the build plate (mm/s).
    pub first_layer_speed: f64,
    /// Travel speed (mm/s).
    pub travel_speed: f64,
    /// Fastest the tool tip moves (mm/s), the firmware's feed-rate limit: programmed speeds
    /// above it are taken at it by the time estimate. Optional: no limit when left out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_speed: Option<f64>,
    /// Acceleration of printing moves (mm/s²), for the estimate's trapezoidal speed profiles.
    /// Optional: when left out, every move is taken at its programmed speed throughout.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_acceleration: Option<f64>,
    /// Acceleration of travel moves (mm/s²). Optional: `max_acceleration` when left out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub travel_acceleration: Option<f64>,
    /// Jerk (mm/s): the largest sudden change of the tool tip's velocity vector, at a corner
    /// or starting from and coming to a stop, that the firmware takes without slowing down
    /// first. Optional: [`DEFAULT_JERK`] when left out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_jerk: Option<f64>,
    /// Nozzle temperature (°C).
    pub nozzle_temperature: f64,
    /// Bed temperature (°C); 0 for no heated bed.
    pub bed_temperature: f64,
    /// Printable size in X, Y and Z (mm).
    pub bed_size: [f64; 3],
    /// true: the machine's X0 Y0 is the bed centre (deltas, rotary tables); false: X0 Y0 is a
    /// bed corner, so the bed spans `0..bed_size` in X and Y. Either way the post places the
    /// part's XY bounding-box centre on the bed centre.
    pub bed_origin_centre: bool,
    /// Filament retracted before a travel that follows printing (mm); 0 for none.
    pub retraction_length: f64,
    /// Speed of retraction and un-retraction (mm/s).
    pub retraction_speed: f64,
    /// Nozzle lift during travel moves (mm); 0 for none.
    pub z_hop: f64,
    /// Highest F (mm/min, or degrees/min for a move of the rotary axes alone) a program may
    /// give. Optional: 60 × `travel_speed` when left out. The speeds of the profile must fit
    /// under it; the delta5 post clamps the feeds it scales to it (with a warning).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_feed_mm_min: Option<f64>,
    /// Part-cooling fan (%, 0..100) while printing beads above the first layer: `M106 S..`
    /// (0..255), `M107` at 0. Optional, 0 when left out (Marlin and delta5).
    #[serde(default)]
    pub fan_speed: f64,
    /// Part-cooling fan (%, 0..100) while printing beads resting on the build plate. Optional,
    /// 0 when left out.
    #[serde(default)]
    pub fan_first_layer: f64,
    /// G-code run before the part (Marlin and delta5), with `{placeholder}`s
    /// ([`crate::custom::PLACEHOLDERS`]). Optional: the kind's default
    /// ([`crate::custom::MARLIN_START`], [`crate::custom::DELTA5_START`]) when left out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start_gcode: Option<String>,
    /// G-code run after the part, once the post has retracted and lifted the nozzle, with
    /// placeholders as `start_gcode`. Optional: the kind's default when left out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub end_gcode: Option<String>,
    /// The print head's shape (`[head]` table: a nozzle cone under a body cylinder), for the
    /// collision check; the built-in profiles have [`collide::Head::default`], which a profile
    /// without the table gets too.
    #[serde(default)]
    pub head: collide::Head,
    /// Tallest pedestal (mm) a plan may print under the part to lift it off the table where
    /// the head meets it (issue 31, the process key `pedestal`). Optional:
    /// [`DEFAULT_MAX_PEDESTAL_HEIGHT`] when left out ([`MachineProfile::max_pedestal_height`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_pedestal_height: Option<f64>,
    /// The bed's kinematics (`[delta5]` table); required when `kind = "delta5"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub delta5: Option<crate::delta5::geometry::Delta5Geometry>,
    /// The robot cell (`[kuka]` table); required when `kind = "kuka"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kuka: Option<crate::kuka::cell::KukaCell>,
}

/// The jerk (mm/s) of a profile that gives an acceleration but no `max_jerk`: Marlin's
/// classic default for X and Y.
pub const DEFAULT_JERK: f64 = 10.0;

/// The tallest pedestal (mm) of a profile that does not say (`max_pedestal_height`).
pub const DEFAULT_MAX_PEDESTAL_HEIGHT: f64 = 40.0;

/// The narrowest bead a nozzle lays well, as a share of its diameter, when a profile does
/// not say (`min_bead_width`).
pub const MIN_BEAD_SHARE: f64 = 0.6;

impl MachineProfile {
    /// The built-in profile of `kind`, parsed from the bundled `profiles/<kind>.toml`.
    pub fn builtin(kind: MachineKind) -> MachineProfile {
        // The bundled files are checked by the test `builtin_profiles_parse_and_validate`.
        MachineProfile::from_toml(MachineProfile::builtin_toml(kind))
            .expect("bundled machine profile is valid")
    }

    /// The bundled `profiles/<kind>.toml` text of the built-in profile of `kind`, comments kept.
    pub fn builtin_toml(kind: MachineKind) -> &'static str {
        match kind {
            MachineKind::Marlin => MARLIN_TOML,
            MachineKind::Delta5 => DELTA5_TOML,
            MachineKind::Kuka => KUKA_TOML,
        }
    }

    /// Reads a profile from TOML text and validates it ([`MachineProfile::validate`]).
    pub fn from_toml(text: &str) -> Result<Self, PostError> {
        let profile: MachineProfile = toml::from_str(text).map_err(|e| {
            let message = one_line(e.message());
            match e.span().and_then(|s| text.get(..s.start)) {
                Some(before) => {
                    let line = before.bytes().filter(|&b| b == b'\n').count() + 1;
                    PostError::ProfileSyntax(format!("line {line}: {message}"))
                }
                None => PostError::ProfileSyntax(message),
            }
        })?;
        profile.validate()?;
        Ok(profile)
    }

    /// The profile as TOML text (without the comments of the bundled files).
    pub fn to_toml(&self) -> String {
        // Serialising a struct of strings, numbers and an array cannot fail.
        toml::to_string(self).unwrap_or_default()
    }

    /// Checks that every figure is finite and in range: diameters, widths, speeds and bed
    /// sizes positive; temperatures, retraction and z-hop not negative (and temperatures
    /// below 500 °C); the name not empty.
    pub fn validate(&self) -> Result<(), PostError> {
        let bad = |field: &'static str, reason: String| PostError::ProfileValue {
            name: self.name.clone(),
            field,
            reason,
        };
        if self.name.trim().is_empty() {
            return Err(bad("name", "must not be empty".into()));
        }
        let positive = [
            ("nozzle_diameter", self.nozzle_diameter),
            ("filament_diameter", self.filament_diameter),
            ("bead_width", self.bead_width),
            ("print_speed", self.print_speed),
            ("first_layer_speed", self.first_layer_speed),
            ("travel_speed", self.travel_speed),
            ("retraction_speed", self.retraction_speed),
            ("bed_size", self.bed_size[0]),
            ("bed_size", self.bed_size[1]),
            ("bed_size", self.bed_size[2]),
        ];
        for (field, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(field, format!("must be a positive number, got {v}")));
            }
        }
        if let Some(d) = self.filament_density {
            if !(d.is_finite() && d > 0.0 && d < 30.0) {
                return Err(bad(
                    "filament_density",
                    format!("must be a density in g/cm3 between 0 and 30, got {d}"),
                ));
            }
        }
        for (field, v, max) in [
            ("max_speed", self.max_speed, 10_000.0),
            ("max_acceleration", self.max_acceleration, 1e6),
            ("travel_acceleration", self.travel_acceleration, 1e6),
            ("max_jerk", self.max_jerk, 10_000.0),
        ] {
            if let Some(v) = v {
                if !(v.is_finite() && v > 0.0 && v <= max) {
                    return Err(bad(
                        field,
                        format!("must be a positive number at most {max}, got {v}"),
                    ));
                }
            }
        }
        if let Some(w) = self.min_bead_width {
            if !(w.is_finite() && w > 0.0 && w <= self.bead_width) {
                return Err(bad(
                    "min_bead_width",
                    format!(
                        "must be positive and at most bead_width {}, got {w}",
                        self.bead_width
                    ),
                ));
            }
        }
        if let Some(h) = self.max_pedestal_height {
            if !(h.is_finite() && (0.0..=self.bed_size[2]).contains(&h)) {
                return Err(bad(
                    "max_pedestal_height",
                    format!(
                        "must be 0 mm or more and at most the bed's height {}, got {h}",
                        self.bed_size[2]
                    ),
                ));
            }
        }
        let non_negative = [
            ("nozzle_temperature", self.nozzle_temperature),
            ("bed_temperature", self.bed_temperature),
            ("retraction_length", self.retraction_length),
            ("z_hop", self.z_hop),
        ];
        for (field, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return Err(bad(field, format!("must be zero or positive, got {v}")));
            }
        }
        for (field, v) in [
            ("nozzle_temperature", self.nozzle_temperature),
            ("bed_temperature", self.bed_temperature),
        ] {
            if v >= 500.0 {
                return Err(bad(field, format!("must be below 500 °C, got {v}")));
            }
        }
        self.validate_limits()?;
        for (field, v) in [
            ("fan_speed", self.fan_speed),
            ("fan_first_layer", self.fan_first_layer),
        ] {
            if !(v.is_finite() && (0.0..=100.0).contains(&v)) {
                return Err(bad(field, format!("must be a percentage 0..100, got {v}")));
            }
        }
        for (field, text) in [
            ("start_gcode", &self.start_gcode),
            ("end_gcode", &self.end_gcode),
        ] {
            if let Some(reason) = text.as_deref().and_then(crate::custom::unknown_placeholder) {
                return Err(bad(field, reason));
            }
        }
        match (self.kind, &self.delta5, &self.kuka) {
            (MachineKind::Delta5, None, _) => return Err(self.missing_table("[delta5]", "delta5")),
            (MachineKind::Kuka, _, None) => return Err(self.missing_table("[kuka]", "kuka")),
            _ => {}
        }
        self.head
            .validate()
            .map_err(|(field, reason)| bad(field, reason))?;
        if let Some(d) = &self.delta5 {
            d.validate(&self.name)?;
        }
        if let Some(k) = &self.kuka {
            k.validate(&self.name)?;
        }
        Ok(())
    }

    /// Checks the upper limits of the figures (past them a figure is a typo: mm for µm, mm/min
    /// for mm/s) and that every speed is within the machine's largest feed.
    fn validate_limits(&self) -> Result<(), PostError> {
        let bad = |field: &'static str, reason: String| PostError::ProfileValue {
            name: self.name.clone(),
            field,
            reason,
        };
        // Figures past these are typos (mm for µm, mm/min for mm/s), and would make absurd
        // programs.
        for (field, v, max) in [
            ("nozzle_diameter", self.nozzle_diameter, 50.0),
            ("filament_diameter", self.filament_diameter, 50.0),
            ("bead_width", self.bead_width, 50.0),
            ("print_speed", self.print_speed, 10_000.0),
            ("first_layer_speed", self.first_layer_speed, 10_000.0),
            ("travel_speed", self.travel_speed, 10_000.0),
            ("retraction_speed", self.retraction_speed, 10_000.0),
            ("retraction_length", self.retraction_length, 1_000.0),
            ("z_hop", self.z_hop, 1_000.0),
            ("bed_size", self.bed_size[0], 1e6),
            ("bed_size", self.bed_size[1], 1e6),
            ("bed_size", self.bed_size[2], 1e6),
        ] {
            if v > max {
                return Err(bad(field, format!("must be at most {max}, got {v}")));
            }
        }
        let max_feed = self.max_feed_mm_min();
        if !(max_feed.is_finite() && max_feed > 0.0) {
            return Err(bad(
                "max_feed_mm_min",
                format!("must be a positive number, got {max_feed}"),
            ));
        }
        for (field, speed) in [
            ("print_speed", self.print_speed),
            ("first_layer_speed", self.first_layer_speed),
            ("travel_speed", self.travel_speed),
            ("retraction_speed", self.retraction_speed),
        ] {
            if speed * 60.0 > max_feed + crate::tolerance::FEED_SLACK {
                return Err(bad(
                    field,
                    format!(
                        "{speed} mm/s is F{} mm/min, above max_feed_mm_min {max_feed}",
                        speed * 60.0
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Checks that the profile is for `kind` and valid ([`MachineProfile::validate`]): the
    /// first thing every post does.
    pub fn check_for(&self, kind: MachineKind) -> Result<(), PostError> {
        if self.kind != kind {
            return Err(PostError::WrongMachine {
                name: self.name.clone(),
                kind: self.kind,
                expected: kind,
            });
        }
        self.validate()
    }

    /// The error for a profile of `kind` without its `table`.
    fn missing_table(&self, table: &'static str, kind: &str) -> PostError {
        PostError::ProfileValue {
            name: self.name.clone(),
            field: table,
            reason: format!("table is required for kind = \"{kind}\""),
        }
    }

    /// [`MachineProfile::check_for`] a `delta5` profile, and its `[delta5]` table.
    pub fn delta5_table(&self) -> Result<&crate::delta5::geometry::Delta5Geometry, PostError> {
        self.check_for(MachineKind::Delta5)?;
        self.delta5
            .as_ref()
            .ok_or_else(|| self.missing_table("[delta5]", "delta5"))
    }

    /// [`MachineProfile::check_for`] a `kuka` profile, and its `[kuka]` table.
    pub fn kuka_table(&self) -> Result<&crate::kuka::cell::KukaCell, PostError> {
        self.check_for(MachineKind::Kuka)?;
        self.kuka
            .as_ref()
            .ok_or_else(|| self.missing_table("[kuka]", "kuka"))
    }

    /// Filament length (mm) fed for a bead of width `w`, thickness `dl` and length `len`:
    /// `4·w·dl·len / (π·D²)` with this profile's filament diameter D (Isa & Lazoglu 2019,
    /// Eq. 1). For planners; the posts only write the `e` the planner computed.
    pub fn filament_length(&self, w: f64, dl: f64, len: f64) -> f64 {
        self.bead().filament_length(w, dl, len)
    }

    /// The tallest pedestal a plan may print under the part (mm): `max_pedestal_height`, or
    /// [`DEFAULT_MAX_PEDESTAL_HEIGHT`].
    pub fn max_pedestal_height(&self) -> f64 {
        self.max_pedestal_height
            .unwrap_or(DEFAULT_MAX_PEDESTAL_HEIGHT)
    }

    /// The narrowest bead the nozzle lays well: `min_bead_width`, or 0.6 × the nozzle.
    pub fn min_bead_width(&self) -> f64 {
        self.min_bead_width
            .unwrap_or(MIN_BEAD_SHARE * self.nozzle_diameter)
    }

    /// The highest F a program may give: `max_feed_mm_min`, or 60 × `travel_speed`.
    pub fn max_feed_mm_min(&self) -> f64 {
        self.max_feed_mm_min.unwrap_or(60.0 * self.travel_speed)
    }

    /// The `S` of `M106` (0..255) for the fan on beads resting on the plate (`first_layer`)
    /// or above: `fan_first_layer` or `fan_speed` as a share of 255.
    pub fn fan_pwm(&self, first_layer: bool) -> u8 {
        let pct = if first_layer {
            self.fan_first_layer
        } else {
            self.fan_speed
        };
        (pct.clamp(0.0, 100.0) * 2.55).round() as u8
    }

    /// The start G-code with its placeholders filled in: `start_gcode`, or the kind's default
    /// (none for KUKA).
    pub fn start_gcode_text(&self) -> String {
        self.start_gcode_text_at(crate::custom::PURGE_THICKNESS)
    }

    /// [`MachineProfile::start_gcode_text`] for a program whose first layer lies at machine Z
    /// `first_layer_z` (its beads' thickness): `{first_layer_z}` and `{purge_e}` follow it, so
    /// a purge line written there lies on the first layer's height.
    pub fn start_gcode_text_at(&self, first_layer_z: f64) -> String {
        let default = match self.kind {
            MachineKind::Marlin => crate::custom::MARLIN_START,
            MachineKind::Delta5 => crate::custom::DELTA5_START,
            MachineKind::Kuka => "",
        };
        let text = self.start_gcode.as_deref().unwrap_or(default);
        crate::custom::expand(text, &self.placeholder_values(first_layer_z))
    }

    /// The end G-code with its placeholders filled in: `end_gcode`, or the kind's default.
    pub fn end_gcode_text(&self) -> String {
        let default = match self.kind {
            MachineKind::Marlin => crate::custom::MARLIN_END,
            MachineKind::Delta5 => crate::custom::DELTA5_END,
            MachineKind::Kuka => "",
        };
        let text = self.end_gcode.as_deref().unwrap_or(default);
        crate::custom::expand(
            text,
            &self.placeholder_values(crate::custom::PURGE_THICKNESS),
        )
    }

    /// The value of every placeholder of [`crate::custom::PLACEHOLDERS`] for this profile,
    /// the first layer at machine Z `first_layer_z`.
    fn placeholder_values(&self, first_layer_z: f64) -> Vec<(&'static str, String)> {
        use toolpath::fixed;
        let (x0, y0) = if self.bed_origin_centre {
            (-self.bed_size[0] / 2.0, -self.bed_size[1] / 2.0)
        } else {
            (0.0, 0.0)
        };
        let feed = |v: f64| fixed(v * 60.0, 0);
        let mm = |v: f64| fixed(v, 3);
        vec![
            ("nozzle_temperature", fixed(self.nozzle_temperature, 0)),
            ("bed_temperature", fixed(self.bed_temperature, 0)),
            ("bed_x", mm(self.bed_size[0])),
            ("bed_y", mm(self.bed_size[1])),
            ("bed_z", mm(self.bed_size[2])),
            ("x_min", mm(x0)),
            ("x_max", mm(x0 + self.bed_size[0])),
            ("y_min", mm(y0)),
            ("y_max", mm(y0 + self.bed_size[1])),
            ("print_feed", feed(self.print_speed)),
            ("first_layer_feed", feed(self.first_layer_speed)),
            ("travel_feed", feed(self.travel_speed)),
            ("retraction_length", fixed(self.retraction_length, 5)),
            ("retraction_feed", feed(self.retraction_speed)),
            ("first_layer_z", mm(first_layer_z)),
            (
                "purge_e",
                fixed(
                    self.filament_length(self.bead_width, first_layer_z, 100.0),
                    5,
                ),
            ),
        ]
    }

    /// The profile's bead: its `bead_width` and `filament_diameter`.
    pub fn bead(&self) -> Bead {
        Bead {
            width: self.bead_width,
            filament_diameter: self.filament_diameter,
        }
    }
}

/// `s` on one line: line breaks and runs of spaces become single spaces.
fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtin_profiles_parse_and_validate() {
        for kind in MachineKind::ALL {
            let p = MachineProfile::builtin(kind);
            assert_eq!(p.kind, kind);
            p.validate().unwrap();
            assert_eq!(p.nozzle_diameter, 0.4);
            assert_eq!(p.filament_diameter, 1.75);
            assert_eq!(p.bead_width, 0.45);
            assert_eq!(p.print_speed, 40.0);
            assert_eq!(p.first_layer_speed, 20.0);
            assert_eq!(p.travel_speed, 120.0);
            assert_eq!((p.nozzle_temperature, p.bed_temperature), (210.0, 60.0));
            assert_eq!((p.retraction_length, p.retraction_speed), (0.8, 35.0));
            assert_eq!(p.z_hop, 0.2);
            assert_eq!(MachineKind::from_name(kind.as_str()), Some(kind));
        }
        for kind in MachineKind::ALL {
            // The head of issue 18, exactly.
            let h = MachineProfile::builtin(kind).head;
            assert_eq!(h.nozzle_tip_radius, 0.5);
            assert_eq!(h.nozzle_cone_half_angle_deg, 30.0);
            assert_eq!(h.nozzle_length, 8.0);
            assert_eq!(h.body_radius, 20.0);
            assert_eq!(h.body_length, 60.0);
        }
        let d = MachineProfile::builtin(MachineKind::Delta5);
        assert_eq!(d.delta5.map(|g| g.table_radius), Some(100.0));
        let m = MachineProfile::builtin(MachineKind::Marlin);
        assert_eq!(m.bed_size, [220.0, 220.0, 250.0]);
        assert!(!m.bed_origin_centre);
    }

    #[test]
    fn builtin_start_and_end_gcode_are_the_defaults() {
        use crate::custom::{DELTA5_END, DELTA5_START, MARLIN_END, MARLIN_START};
        let m = MachineProfile::builtin(MachineKind::Marlin);
        assert_eq!(m.start_gcode.as_deref(), Some(MARLIN_START));
        assert_eq!(m.end_gcode.as_deref(), Some(MARLIN_END));
        let d = MachineProfile::builtin(MachineKind::Delta5);
        assert_eq!(d.start_gcode.as_deref(), Some(DELTA5_START));
        assert_eq!(d.end_gcode.as_deref(), Some(DELTA5_END));
        assert_eq!((m.fan_speed, m.fan_first_layer), (100.0, 0.0));
        assert_eq!(m.fan_pwm(false), 255);
        assert_eq!(m.fan_pwm(true), 0);
        // Filled in: no braces left, the temperatures and the bed's edges written.
        let start = m.start_gcode_text();
        assert!(!start.contains('{'), "{start}");
        assert!(
            start.contains("M104 S210") && start.contains("M190 S60"),
            "{start}"
        );
        assert!(start.contains("G0 X0.000 Y0.000 Z0.300 F7200"), "{start}");
        let at = m.start_gcode_text_at(0.2);
        assert!(at.contains("G0 X0.000 Y0.000 Z0.200 F7200"), "{at}");
        // A misspelt placeholder names the key and the placeholder.
        let bad = MARLIN_TOML.replace("M104 S{nozzle_temperature}", "M104 S{nozle_temperature}");
        let e = MachineProfile::from_toml(&bad).unwrap_err().to_string();
        assert!(
            e.contains("start_gcode") && e.contains("{nozle_temperature}"),
            "{e}"
        );
        // A feed above max_feed_mm_min, and a fan above 100 %.
        let fast = MARLIN_TOML.replace("max_feed_mm_min = 12000.0", "max_feed_mm_min = 6000.0");
        let e = MachineProfile::from_toml(&fast).unwrap_err().to_string();
        assert!(
            e.contains("travel_speed") && e.contains("max_feed_mm_min"),
            "{e}"
        );
        let loud = MARLIN_TOML.replace("fan_speed = 100.0", "fan_speed = 255.0");
        let e = MachineProfile::from_toml(&loud).unwrap_err().to_string();
        assert!(e.contains("fan_speed"), "{e}");
    }

    #[test]
    fn profile_toml_round_trip() {
        let m = MachineProfile::builtin(MachineKind::Kuka);
        assert_eq!(MachineProfile::from_toml(&m.to_toml()).unwrap(), m);
    }

    #[test]
    fn profile_errors_are_one_line() {
        let unknown = MARLIN_TOML.replace("z_hop = 0.2", "z_hop = 0.2\nzhop = 1.0");
        let missing = MARLIN_TOML.replace("z_hop = 0.2", "");
        let bad_kind = MARLIN_TOML.replace("kind = \"marlin\"", "kind = \"prusa\"");
        let negative = MARLIN_TOML.replace("print_speed = 40.0", "print_speed = -40.0");
        let nan = MARLIN_TOML.replace("bead_width = 0.45", "bead_width = nan");
        let hot = MARLIN_TOML.replace("nozzle_temperature = 210.0", "nozzle_temperature = 2100.0");
        let wide = MARLIN_TOML.replace("min_bead_width = 0.24", "min_bead_width = 0.5");
        let no_accel =
            MARLIN_TOML.replace("max_acceleration = 1000.0", "max_acceleration = -1000.0");
        let zero_jerk = MARLIN_TOML.replace("max_jerk = 10.0", "max_jerk = 0.0");
        let mm_min = MARLIN_TOML.replace("max_speed = 200.0", "max_speed = 12000.0");
        for (text, needle) in [
            (no_accel.as_str(), "max_acceleration"),
            (zero_jerk.as_str(), "max_jerk"),
            (mm_min.as_str(), "max_speed"),
            (wide.as_str(), "min_bead_width"),
            (unknown.as_str(), "zhop"),
            (missing.as_str(), "z_hop"),
            (bad_kind.as_str(), "prusa"),
            (negative.as_str(), "print_speed"),
            (nan.as_str(), "bead_width"),
            (hot.as_str(), "nozzle_temperature"),
            ("", "name"),
            ("\u{0}\u{ff}[[[", "machine profile"),
        ] {
            let e = MachineProfile::from_toml(text).unwrap_err().to_string();
            assert!(e.contains(needle), "{e}");
            assert!(!e.contains('\n'), "{e}");
        }
        let e = MachineProfile::from_toml(&unknown).unwrap_err().to_string();
        assert!(e.contains("line "), "{e}");
        // Left out, the narrowest bead is 0.6 x the nozzle.
        let old =
            MachineProfile::from_toml(&MARLIN_TOML.replace("min_bead_width = 0.24", "")).unwrap();
        assert_eq!(old.min_bead_width, None);
        assert!((old.min_bead_width() - 0.6 * old.nozzle_diameter).abs() < 1e-12);
        // The motion limits are optional: left out, none.
        let mut free = MARLIN_TOML.to_string();
        for key in [
            "max_speed = 200.0",
            "max_acceleration = 1000.0",
            "travel_acceleration = 1500.0",
            "max_jerk = 10.0",
        ] {
            free = free.replace(key, "");
        }
        let free = MachineProfile::from_toml(&free).unwrap();
        assert_eq!(
            (
                free.max_speed,
                free.max_acceleration,
                free.travel_acceleration,
                free.max_jerk
            ),
            (None, None, None, None)
        );
    }

    #[test]
    fn process_file_documents_the_defaults() {
        let v: toml::Table = toml::from_str(PROCESS_TOML).unwrap();
        let d = v["defaults"].as_table().unwrap();
        assert!(d["tolerance"].as_float().unwrap() > 0.0);
        assert_eq!(d["layer_height_pattern"].as_str(), Some("uniform"));
        assert_eq!(d["uniform_layer_height"].as_float(), Some(0.2));
        assert_eq!(d["path_mode"].as_str(), Some("contour_zigzag"));
        assert_eq!(d["filling_ratio"].as_float(), Some(1.0));
        assert_eq!(d["perimeters"].as_integer(), Some(2));
        assert_eq!(d["raster_angle_deg"].as_float(), Some(45.0));
        assert_eq!(d["pedestal"].as_str(), Some("auto"));
        assert_eq!(d["pedestal_inset"].as_float(), Some(0.0));
        // The tallest pedestal: the built-in 5-axis and robot profiles say it, a profile
        // without it gets the default, and it fits under the bed's height.
        for kind in [MachineKind::Delta5, MachineKind::Kuka] {
            let m = MachineProfile::builtin(kind);
            assert_eq!(m.max_pedestal_height, Some(DEFAULT_MAX_PEDESTAL_HEIGHT));
            let over = MachineProfile {
                max_pedestal_height: Some(m.bed_size[2] + 1.0),
                ..m.clone()
            };
            assert!(over.validate().is_err());
            let none = MachineProfile {
                max_pedestal_height: None,
                ..m
            };
            assert_eq!(none.max_pedestal_height(), DEFAULT_MAX_PEDESTAL_HEIGHT);
        }
        // The example override is commented out, and valid once uncommented.
        assert!(!v.contains_key("features"));
        let uncommented: String = PROCESS_TOML
            .lines()
            .map(|l| {
                l.strip_prefix("# ")
                    .filter(|r| r.starts_with("[features.") || r.contains(" = "))
                    .unwrap_or(l)
            })
            .collect::<Vec<_>>()
            .join("\n");
        let v: toml::Table = toml::from_str(&uncommented).unwrap();
        assert!(v["features"]["1"]
            .as_table()
            .unwrap()
            .contains_key("perimeters"));
    }

    #[test]
    fn extrusion_follows_isa_lazoglu_eq1() {
        let m = MachineProfile::builtin(MachineKind::Marlin);
        // 0.45 x 0.2 bead, 10 mm long, 1.75 mm filament: 0.9 mm³ / 2.405 mm² = 0.37418 mm.
        let e = m.filament_length(0.45, 0.2, 10.0);
        assert!((e - 0.9 / (std::f64::consts::PI * 1.75 * 1.75 / 4.0)).abs() < 1e-12);
        assert!((e - 0.37418).abs() < 1e-5);
    }
}

//! What a Marlin program says about the machine and the settings it was made with, in the
//! words slicers' G-code viewers use: the `; bed_shape = ` line of the header, and the config
//! block at the end of the program (`; prusaslicer_config = begin` … `= end`, one
//! `; key = value` line each, keys sorted).
//!
//! PrusaSlicer's G-code viewer reads that block only from programs whose header says they
//! were made by PrusaSlicer or Slic3r, which ours do not claim: it then sizes its bed to the
//! tool paths (10 mm around them). Other tools read the block by its delimiters, and a user
//! can see there what the program was made for. No comment of ours names a slicer's product
//! ([`VIEWER_PRODUCERS`]): the viewer would take the program for that slicer's, and refuse it
//! when the config block is not the whole of that slicer's.

use crate::machine::MachineProfile;
use toolpath::{fixed, MoveKind, ToolPath};

/// The words PrusaSlicer's G-code viewer (2.5 to 2.8) looks for in a comment to tell which
/// slicer made a program (its `GCodeProcessor::Producers`); none of our comments holds one.
pub const VIEWER_PRODUCERS: [&str; 9] = [
    "PrusaSlicer",
    "Slic3r",
    "SuperSlicer",
    "Cura_SteamEngine",
    "Simplify3D",
    "CraftWare",
    "ideaMaker",
    "KISSlicer",
    "OrcaSlicer",
];

/// The bed's corners in machine X and Y as PrusaSlicer's `bed_shape` writes them
/// (`0x0,220x0,220x220,0x220`; from −110 with `bed_origin_centre`).
pub fn bed_shape(m: &MachineProfile) -> String {
    let (x0, y0) = if m.bed_origin_centre {
        (-m.bed_size[0] / 2.0, -m.bed_size[1] / 2.0)
    } else {
        (0.0, 0.0)
    };
    let (x1, y1) = (x0 + m.bed_size[0], y0 + m.bed_size[1]);
    let n = |v: f64| trimmed(v, 3);
    [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
        .iter()
        .map(|&(x, y)| format!("{}x{}", n(x), n(y)))
        .collect::<Vec<_>>()
        .join(",")
}

/// `v` with `decimals` places, trailing zeros (and a bare point) taken off: `220`, `0.45`.
fn trimmed(v: f64, decimals: usize) -> String {
    let s = fixed(v, decimals);
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// The layer heights of the path's print moves: the first layer's (the first print point's
/// thickness) and the most common one (to the micrometre), or `None` for a path that prints
/// nothing.
pub fn layer_heights(path: &ToolPath) -> Option<(f64, f64)> {
    let mut prints = path.points.iter().filter(|q| q.kind == MoveKind::Print);
    let first = f64::from(prints.next()?.thickness);
    let mut counts: std::collections::BTreeMap<i64, usize> = Default::default();
    for q in path.points.iter().filter(|q| q.kind == MoveKind::Print) {
        *counts
            .entry((f64::from(q.thickness) * 1e3).round() as i64)
            .or_default() += 1;
    }
    let common = counts
        .iter()
        .max_by_key(|(_, &n)| n)
        .map_or(first, |(&um, _)| um as f64 / 1e3);
    Some((first, common))
}

/// The config block's lines: the machine's keys in PrusaSlicer's names (bed, nozzle,
/// filament, widths, temperatures, speeds, retraction, motion limits, fan), the path's layer
/// heights, and `extra` (the plan's: skirt, brim, arc fitting), sorted by key, between
/// `; prusaslicer_config = begin` and `= end`.
pub fn block(m: &MachineProfile, path: &ToolPath, extra: &[(String, String)]) -> String {
    let n = |v: f64| trimmed(v, 4);
    let w = n(m.bead_width);
    let mut keys: Vec<(String, String)> = vec![
        ("bed_shape".into(), bed_shape(m)),
        ("printer_technology".into(), "FFF".into()),
        ("gcode_flavor".into(), "marlin2".into()),
        ("use_relative_e_distances".into(), "1".into()),
        ("nozzle_diameter".into(), n(m.nozzle_diameter)),
        ("filament_diameter".into(), n(m.filament_diameter)),
        ("max_print_height".into(), n(m.bed_size[2])),
        ("temperature".into(), trimmed(m.nozzle_temperature, 0)),
        (
            "first_layer_temperature".into(),
            trimmed(m.nozzle_temperature, 0),
        ),
        ("bed_temperature".into(), trimmed(m.bed_temperature, 0)),
        (
            "first_layer_bed_temperature".into(),
            trimmed(m.bed_temperature, 0),
        ),
        ("perimeter_speed".into(), n(m.print_speed)),
        ("external_perimeter_speed".into(), n(m.print_speed)),
        ("infill_speed".into(), n(m.print_speed)),
        ("solid_infill_speed".into(), n(m.print_speed)),
        ("first_layer_speed".into(), n(m.first_layer_speed)),
        ("travel_speed".into(), n(m.travel_speed)),
        ("retract_length".into(), n(m.retraction_length)),
        ("retract_speed".into(), n(m.retraction_speed)),
        ("retract_lift".into(), n(m.z_hop)),
        ("max_fan_speed".into(), trimmed(m.fan_speed, 0)),
        ("min_fan_speed".into(), trimmed(m.fan_speed, 0)),
        ("cooling".into(), u8::from(m.fan_speed > 0.0).to_string()),
    ];
    for key in [
        "extrusion_width",
        "first_layer_extrusion_width",
        "perimeter_extrusion_width",
        "external_perimeter_extrusion_width",
        "infill_extrusion_width",
        "solid_infill_extrusion_width",
        "top_infill_extrusion_width",
        "support_material_extrusion_width",
    ] {
        keys.push((key.into(), w.clone()));
    }
    if let Some(d) = m.filament_density {
        keys.push(("filament_density".into(), n(d)));
    }
    let sane = |t: &f64| *t > 0.0 && *t <= m.bed_size[2];
    if let Some((first, common)) = layer_heights(path) {
        if let (true, true) = (sane(&first), sane(&common)) {
            keys.push(("first_layer_height".into(), n(first)));
            keys.push(("layer_height".into(), n(common)));
        }
    }
    let travel = m.travel_acceleration.or(m.max_acceleration);
    let limits = [
        ("machine_max_acceleration_extruding", m.max_acceleration),
        ("machine_max_acceleration_travel", travel),
        ("machine_max_jerk_x", m.max_jerk),
        ("machine_max_jerk_y", m.max_jerk),
        ("machine_max_feedrate_x", m.max_speed),
        ("machine_max_feedrate_y", m.max_speed),
    ];
    for (key, v) in limits {
        if let Some(v) = v {
            keys.push((key.into(), n(v)));
        }
    }
    if limits.iter().any(|(_, v)| v.is_some()) {
        keys.push(("machine_limits_usage".into(), "emit_to_gcode".into()));
    }
    for (k, v) in extra {
        keys.retain(|(have, _)| have != k);
        keys.push((k.clone(), v.clone()));
    }
    keys.sort();
    let mut out = String::from("\n; prusaslicer_config = begin\n");
    for (k, v) in keys {
        out.push_str(&format!("; {k} = {}\n", crate::gcode::comment_text(&v)));
    }
    out.push_str("; prusaslicer_config = end\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::MachineKind;

    #[test]
    fn the_bed_is_its_four_corners() {
        let mut m = MachineProfile::builtin(MachineKind::Marlin);
        assert_eq!(bed_shape(&m), "0x0,220x0,220x220,0x220");
        m.bed_origin_centre = true;
        m.bed_size = [200.0, 150.5, 100.0];
        assert_eq!(bed_shape(&m), "-100x-75.25,100x-75.25,100x75.25,-100x75.25");
    }

    #[test]
    fn the_block_is_delimited_sorted_and_names_no_slicer() {
        let m = MachineProfile::builtin(MachineKind::Marlin);
        let extra = [("skirts".to_string(), "1".to_string())];
        let text = block(&m, &ToolPath::default(), &extra);
        let lines: Vec<&str> = text.lines().filter(|l| !l.is_empty()).collect();
        assert_eq!(lines.first(), Some(&"; prusaslicer_config = begin"));
        assert_eq!(lines.last(), Some(&"; prusaslicer_config = end"));
        let keys: Vec<&str> = lines[1..lines.len() - 1]
            .iter()
            .map(|l| l[2..].split(" = ").next().unwrap_or(""))
            .collect();
        let mut sorted = keys.clone();
        sorted.sort();
        assert_eq!(keys, sorted);
        for want in [
            "bed_shape",
            "nozzle_diameter",
            "printer_technology",
            "skirts",
        ] {
            assert!(keys.contains(&want), "{want}");
        }
        assert!(text.contains("; printer_technology = FFF\n"));
        assert!(!VIEWER_PRODUCERS.iter().any(|p| text.contains(p)));
    }
}

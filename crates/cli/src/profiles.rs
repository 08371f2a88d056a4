//! `features profiles`: the built-in machine and process profiles, listed or printed as TOML
//! to copy and edit (`features profiles show delta5 > my.toml`, then `--machine-profile
//! my.toml`).

use crate::{emit, Failure, ProfilesAction, ProfilesArgs};
use robot_post::machine::{MachineKind, MachineProfile, PROCESS_TOML};

/// Runs the command.
pub fn run(args: &ProfilesArgs) -> Result<(), Failure> {
    match &args.action {
        None => emit(&listing()),
        Some(ProfilesAction::Show { name }) => emit(show(name)?),
    }
}

/// One line per built-in profile.
fn listing() -> String {
    let mut out = String::from(
        "machine profiles (--machine NAME; to edit one: features profiles show NAME > my.toml, then --machine-profile my.toml):\n",
    );
    for kind in MachineKind::ALL {
        let m = MachineProfile::builtin(kind);
        out.push_str(&format!(
            "  {:<8} {} (bed {} x {} x {} mm, nozzle {} mm)\n",
            kind.as_str(),
            m.name,
            m.bed_size[0],
            m.bed_size[1],
            m.bed_size[2],
            m.nozzle_diameter
        ));
    }
    let process = plan::Process::default();
    let p = process.base();
    out.push_str(&format!(
        "process profiles (--process FILE; every key with its default and meaning):\n  process  {} mm layers, {} paths, {} perimeters, filling ratio {}, axes smoothed in a {} degree cone\n",
        p.uniform_layer_height,
        serde_json::to_value(p.path_mode)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_default(),
        p.perimeters,
        p.filling_ratio,
        process.orientation.cone_angle_deg
    ));
    out
}

/// The bundled TOML of profile `name`.
fn show(name: &str) -> Result<&'static str, Failure> {
    if name == "process" {
        return Ok(PROCESS_TOML);
    }
    MachineKind::from_name(name)
        .map(MachineProfile::builtin_toml)
        .ok_or_else(|| Failure {
            path: name.to_string(),
            cause: "no such profile: the built-in ones are marlin, delta5, kuka and process (features profiles lists them)".into(),
        })
}

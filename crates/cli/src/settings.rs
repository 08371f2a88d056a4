//! The settings of `features plan`: the process file and the machine profile, read and checked
//! before any work, so that a bad one fails at once.

use crate::{Failure, PlanArgs};
use plan::Process;
use robot_post::machine::{MachineKind, MachineProfile};

/// The process file and the machine profile of a plan, checked, in the order a user fixes them.
pub fn settings(args: &PlanArgs) -> Result<(Process, MachineProfile), Failure> {
    let path = &args.part;
    let settings = args.process.as_deref().unwrap_or(path);
    let process = match &args.process {
        Some(p) => {
            let text = std::fs::read_to_string(p)
                .map_err(|e| Failure::new(p, format!("cannot read process file: {e}")))?;
            Process::from_toml(&text).map_err(|e| Failure::new(p, e))?
        }
        None => Process::default(),
    };
    process
        .validate_defaults()
        .map_err(|e| Failure::new(settings, e))?;
    let machine = match (&args.machine_profile, args.machine.as_deref()) {
        (Some(p), _) => {
            let text = std::fs::read_to_string(p)
                .map_err(|e| Failure::new(p, format!("cannot read machine profile: {e}")))?;
            MachineProfile::from_toml(&text).map_err(|e| Failure::new(p, e))?
        }
        (None, Some(name)) => {
            MachineProfile::builtin(MachineKind::from_name(name).ok_or_else(|| {
                Failure::new(
                    path,
                    format!("unknown machine `{name}` (marlin, delta5 or kuka)"),
                )
            })?)
        }
        (None, None) => MachineProfile::builtin(MachineKind::Marlin),
    };
    process
        .validate_orientation()
        .map_err(|e| Failure::new(settings, e))?;
    Ok((process, machine))
}

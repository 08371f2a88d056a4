//! The kinds of machine, one per post.

use std::fmt;

/// Which post writes the program, and so which motions the machine has.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MachineKind {
    /// A 3-axis Marlin printer: tool axis +Z only.
    Marlin,
    /// A 5-axis printer (three linear axes and a tilting/rotary table).
    Delta5,
    /// A KUKA robot deposition cell.
    Kuka,
}

impl MachineKind {
    /// Every kind, in declaration order.
    pub const ALL: [MachineKind; 3] = [MachineKind::Marlin, MachineKind::Delta5, MachineKind::Kuka];

    /// The kind's name as written in profiles and on the command line (`marlin`, `delta5`,
    /// `kuka`).
    pub fn as_str(self) -> &'static str {
        match self {
            MachineKind::Marlin => "marlin",
            MachineKind::Delta5 => "delta5",
            MachineKind::Kuka => "kuka",
        }
    }

    /// Whether the machine prints only along +Z (its tool axis cannot tilt): `marlin`.
    pub fn plus_z_only(self) -> bool {
        matches!(self, MachineKind::Marlin)
    }

    /// The kind named `name` (as [`MachineKind::as_str`] writes it), if any.
    pub fn from_name(name: &str) -> Option<MachineKind> {
        MachineKind::ALL.into_iter().find(|k| k.as_str() == name)
    }
}

impl fmt::Display for MachineKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

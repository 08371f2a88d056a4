//! The KUKA robot post: KRL `.src`/`.dat` programs for a 6-axis arm carrying the extruder.
//! Work in progress: filled in by the KUKA post.

/// The cell's frames, the arm model and the KRL settings: the `[kuka]` table of a `kuka`
/// machine profile.
#[derive(Debug, Clone, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct KukaCell {}

impl KukaCell {
    /// Checks every figure of the table; `name` is the profile's name for the message.
    pub fn validate(&self, _name: &str) -> Result<(), crate::PostError> {
        Ok(())
    }
}

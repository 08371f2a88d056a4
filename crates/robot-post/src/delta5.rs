//! The 5-axis printer post: a delta (or Cartesian) printer with a tilting (B) and rotating (C)
//! bed (Isa & Lazoglu 2019, §4, Eq. 9–12). Work in progress: filled in by the delta5 post.

/// The bed's geometry and the controller's resolutions: the `[delta5]` table of a `delta5`
/// machine profile.
#[derive(Debug, Clone, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct Delta5Geometry {}

impl Delta5Geometry {
    /// Checks every figure of the table; `name` is the profile's name for the message.
    pub fn validate(&self, _name: &str) -> Result<(), crate::PostError> {
        Ok(())
    }
}

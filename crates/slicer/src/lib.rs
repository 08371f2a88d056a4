//! slicer: placeholder until its issue lands.

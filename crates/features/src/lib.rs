//! features: placeholder until its issue lands.

//! Pipeline file.

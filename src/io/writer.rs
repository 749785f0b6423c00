//! GeoPackage writer.

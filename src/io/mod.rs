//! GDAL I/O.

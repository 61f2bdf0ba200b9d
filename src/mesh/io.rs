//! Mesh files: OBJ, OFF and PLY (being written).

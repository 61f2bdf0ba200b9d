//! Pictures of meshes (being written).

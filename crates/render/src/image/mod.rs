//! Images: files in and out, textures, environment maps.

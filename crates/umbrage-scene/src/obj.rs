//! Wavefront OBJ loading via `tobj`.
//!
//! All objects/groups of the file are merged into one mesh; polygons are triangulated (fan).
//! Positions keep the file's indexing: within one tobj model the indices are used as given;
//! `tobj` splits the file's global vertex list per model, so a vertex that several models
//! share is re-welded by exact (bitwise) position equality across models only.
//! Normals, texture coordinates and materials are ignored.

use glam::Vec3;
use std::collections::HashMap;
use std::io::BufRead;
use std::path::Path;
use umbrage::error::{Error, Result};
use umbrage::geom::Mesh;

fn options() -> tobj::LoadOptions {
    tobj::LoadOptions { triangulate: true, single_index: false, ignore_points: true, ignore_lines: true }
}

/// Loads an OBJ file as one mesh (see the module docs). Errors name the path.
pub fn load_obj(path: &Path) -> Result<Mesh> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| Error::input(&name, format!("cannot read OBJ file: {e}")))?;
    let text = String::from_utf8_lossy(&bytes);
    load_obj_str(&text, &name)
}

/// Loads OBJ text held in memory; `name` is used in error messages.
pub fn load_obj_str(text: &str, name: &str) -> Result<Mesh> {
    check_vertices(text, name)?;
    let mut reader = std::io::BufReader::new(text.as_bytes());
    load_obj_reader(&mut reader, name)
}

/// Rejects `v` lines whose coordinates parse to non-finite f32 values (`nan`, `inf`, 1e39),
/// naming the vertex (1-based, as OBJ counts) and its line.
///
/// Also rejects face (and line) indices that cannot name an element, which tobj 4.0.5 turns
/// into overflowing `usize` arithmetic (`vn * 3 + 2`, `vt * 2 + 1`: a panic in debug builds,
/// an out-of-bounds index in release; found by tests/fuzz/): a positive index larger than the
/// file's line count (every element takes a line of its own), and a negative (relative) index
/// reaching before the first `v`/`vt`/`vn` defined so far.
fn check_vertices(text: &str, name: &str) -> Result<()> {
    let mut count = 0usize;
    let lines = text.lines().count() as u64;
    // v, vt, vn lines so far (what relative indices count back from)
    let mut defined = [0u64; 3];
    for (line_no, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let first = words.next();
        match first {
            Some("vt") => defined[1] += 1,
            Some("vn") => defined[2] += 1,
            Some("f") | Some("l") => {
                for w in words {
                    for (k, part) in w.split('/').enumerate().take(3) {
                        let Ok(x) = part.parse::<i64>() else { continue };
                        let bad = if x < 0 { x.unsigned_abs() > defined[k] } else { x.unsigned_abs() > lines };
                        if bad {
                            let what = ["vertex", "texture coordinate", "normal"][k];
                            return Err(Error::input(
                                format!("{name}:{}", line_no + 1),
                                format!("face {what} index {x} out of range ({} defined so far, {lines} lines)", defined[k]),
                            ));
                        }
                    }
                }
                continue;
            }
            _ => {}
        }
        if first != Some("v") {
            continue;
        }
        defined[0] += 1;
        count += 1;
        for w in words.take(3) {
            if let Ok(x) = w.parse::<f32>() {
                if !x.is_finite() {
                    return Err(Error::input(
                        format!("{name}:{}", line_no + 1),
                        format!("vertex {count} has a non-finite coordinate '{w}'"),
                    ));
                }
            }
        }
    }
    Ok(())
}

fn load_obj_reader(reader: &mut impl BufRead, name: &str) -> Result<Mesh> {
    // Materials are not used: any mtllib fails to load, which tobj records without failing.
    let (models, _materials) = tobj::load_obj_buf(reader, &options(), |_| Err(tobj::LoadError::OpenFileFailed))
        .map_err(|e| Error::input(name, format!("malformed OBJ: {e}")))?;
    let mut positions: Vec<Vec3> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    // position bits -> global index, for vertices of earlier models
    let mut earlier: HashMap<[u32; 3], u32> = HashMap::new();
    for model in &models {
        let m = &model.mesh;
        if m.positions.len() % 3 != 0 || m.indices.len() % 3 != 0 {
            return Err(Error::input(name, format!("malformed OBJ: object '{}' is not a triangle list", model.name)));
        }
        let mut map: Vec<u32> = Vec::with_capacity(m.positions.len() / 3);
        let mut added: Vec<([u32; 3], u32)> = Vec::new();
        for (i, c) in m.positions.chunks_exact(3).enumerate() {
            // tobj's `Float` is f64 with its `use_f64` feature
            #[allow(clippy::unnecessary_cast)]
            let p = Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32);
            if !p.is_finite() {
                return Err(Error::input(
                    name,
                    format!("vertex {} of object '{}' has a non-finite coordinate ({}, {}, {})", i + 1, model.name, c[0], c[1], c[2]),
                ));
            }
            let key = [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
            if let Some(&g) = earlier.get(&key) {
                map.push(g);
            } else {
                let g = positions.len() as u32;
                positions.push(p);
                added.push((key, g));
                map.push(g);
            }
        }
        for (k, g) in added {
            earlier.entry(k).or_insert(g);
        }
        for t in m.indices.chunks_exact(3) {
            let mut tri = [0u32; 3];
            for (k, &i) in t.iter().enumerate() {
                tri[k] = *map.get(i as usize).ok_or_else(|| {
                    Error::input(name, format!("malformed OBJ: face index {} out of range in object '{}'", i + 1, model.name))
                })?;
            }
            triangles.push(tri);
        }
    }
    if triangles.is_empty() {
        return Err(Error::mesh(name, "empty: the OBJ file has no faces"));
    }
    let mesh = Mesh::new(positions, triangles);
    mesh.validate(name)?;
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn data(f: &str) -> PathBuf {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/data").join(f)
    }

    #[test]
    fn cube_loads_closed() {
        let m = load_obj(&data("cube.obj")).unwrap();
        assert_eq!(m.positions.len(), 8);
        assert_eq!(m.triangles.len(), 12);
        crate::shapes::tests_support::assert_closed_outward(&m, "cube.obj");
    }

    #[test]
    fn multi_group_welded() {
        // the same cube, faces split over two objects
        let m = load_obj(&data("cube_groups.obj")).unwrap();
        assert_eq!(m.positions.len(), 8);
        crate::shapes::tests_support::assert_closed_outward(&m, "cube_groups.obj");
    }

    #[test]
    fn malformed() {
        let e = load_obj(&data("malformed.obj")).unwrap_err().to_string();
        assert!(e.contains("malformed.obj") && e.contains("malformed OBJ"), "{e}");
    }

    #[test]
    fn nan_vertex() {
        let e = load_obj(&data("nan_vertex.obj")).unwrap_err().to_string();
        assert!(e.contains("nan_vertex.obj") && e.contains("vertex 3") && e.contains("nan_vertex.obj:4"), "{e}");
    }

    #[test]
    fn no_faces() {
        let e = load_obj(&data("no_faces.obj")).unwrap_err().to_string();
        assert!(e.contains("no_faces.obj") && e.contains("empty"), "{e}");
    }

    #[test]
    fn missing_file() {
        let e = load_obj(&data("does_not_exist.obj")).unwrap_err().to_string();
        assert!(e.contains("does_not_exist.obj"), "{e}");
    }
}

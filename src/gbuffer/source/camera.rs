//! The camera of a render, for view vectors from world positions: where it was (the header's
//! `worldToCamera`, the note lookdev's Blender script writes, or `--camera-position`), whether
//! it was orthographic (the header's `worldToNDC`, or the note), and, for the background,
//! where each pixel looks.

use glam::{DMat3, DVec3, Mat4, Vec3};
use std::collections::BTreeMap;

/// How the camera projects.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Projection {
    Perspective,
    Orthographic,
}

/// A camera in the file's own world coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub position: Vec3,
    /// The direction it looks in, where known (always, for an orthographic camera).
    pub forward: Option<Vec3>,
    pub projection: Projection,
    /// Where it came from, for the report: `worldToCamera`, `--camera-position`, ….
    pub from: String,
}

/// The text attribute lookdev's Blender script writes (Blender's render metadata "Note"):
/// `lookdev.camera position=X,Y,Z forward=X,Y,Z projection=perspective|orthographic`.
pub const NOTE_ATTRIBUTE: &str = "Note";
pub const NOTE_PREFIX: &str = "lookdev.camera";

/// The value of `key=` in lookdev's note, if the header has the note and the note the key.
pub fn note_field<'a>(text: &'a BTreeMap<String, String>, key: &str) -> Option<&'a str> {
    let note = text.get(NOTE_ATTRIBUTE)?.strip_prefix(NOTE_PREFIX)?;
    note.split_whitespace().find_map(|w| w.strip_prefix(key)?.strip_prefix('='))
}

/// The camera the header records: OpenEXR's `worldToCamera` (with `worldToNDC` telling an
/// orthographic camera from a perspective one), else lookdev's note. Matrices are stored for
/// row vectors (`p · M`), and cameras look down their −Z.
pub fn from_header(
    text: &BTreeMap<String, String>,
    matrices: &BTreeMap<String, [[f32; 4]; 4]>,
) -> Result<Option<Camera>, String> {
    if let Some(rows) = matrices.get("worldToCamera") {
        // Rows read as columns give the matrix for column vectors.
        let world_to_camera = Mat4::from_cols_array_2d(rows);
        if world_to_camera.determinant().abs() < 1e-12 || !world_to_camera.is_finite() {
            return Err("the header's worldToCamera matrix cannot be inverted".into());
        }
        let camera_to_world = world_to_camera.inverse();
        let projection = match matrices.get("worldToNDC") {
            // The column that makes w: zero for x, y and z when the projection is orthographic.
            Some(ndc) if ndc[0][3] == 0.0 && ndc[1][3] == 0.0 && ndc[2][3] == 0.0 => Projection::Orthographic,
            _ => Projection::Perspective,
        };
        return Ok(Some(Camera {
            position: camera_to_world.transform_point3(Vec3::ZERO),
            forward: camera_to_world.transform_vector3(-Vec3::Z).try_normalize(),
            projection,
            from: "the header's worldToCamera".into(),
        }));
    }
    let Some(note) = text.get(NOTE_ATTRIBUTE).and_then(|n| n.strip_prefix(NOTE_PREFIX)) else {
        return Ok(None);
    };
    let field = |key: &str| note.split_whitespace().find_map(|w| w.strip_prefix(&format!("{key}=")));
    let vector = |key: &str| -> Result<Vec3, String> {
        let text = field(key).ok_or_else(|| format!("the header's camera note has no {key}"))?;
        parse_vector(text).ok_or_else(|| format!("the header's camera note has {key}={text}, not three numbers"))
    };
    let projection = match field("projection") {
        Some("perspective") | None => Projection::Perspective,
        Some("orthographic") => Projection::Orthographic,
        Some(other) => return Err(format!("the header's camera note has projection={other}")),
    };
    Ok(Some(Camera {
        position: vector("position")?,
        forward: vector("forward")?.try_normalize(),
        projection,
        from: "the header's camera note (lookdev's Blender script)".into(),
    }))
}

/// `X,Y,Z`: three finite numbers.
pub fn parse_vector(text: &str) -> Option<Vec3> {
    let values: Vec<f32> = text.split(',').map(|v| v.trim().parse().ok()).collect::<Option<_>>()?;
    match values[..] {
        [x, y, z] if [x, y, z].iter().all(|v| v.is_finite()) => Some(Vec3::new(x, y, z)),
        _ => None,
    }
}

/// View vectors for every pixel: toward the camera from each wholly covered pixel's position;
/// for an orthographic camera, its reversed axis; for the edges and the background of a
/// perspective camera, the reversed ray through the pixel, from the rays of the covered pixels
/// (a pinhole's rays are a linear function of the pixel coordinates, fitted here).
pub fn view_vectors(camera: &Camera, positions: &[Vec3], coverage: &[f32], width: usize, height: usize) -> Vec<Vec3> {
    if let (Projection::Orthographic, Some(forward)) = (camera.projection, camera.forward) {
        return vec![-forward; positions.len()];
    }
    let toward = |p: Vec3| (camera.position - p).try_normalize();
    let rays = fit_rays(camera.position, positions, coverage, width, height);
    let fallback = camera.forward.map_or(Vec3::Z, |f| -f);
    (0..positions.len())
        .map(|i| {
            let ray = || rays.map(|a| -ray_at(&a, i % width, i / width, width, height));
            // A filtered position at an edge mixes the surface's with the background's: there,
            // as on the background, the pinhole's ray through the pixel's centre is exact.
            let v = if coverage[i] >= 0.999 { toward(positions[i]) } else { ray().and_then(Vec3::try_normalize) };
            v.or_else(|| toward(positions[i])).unwrap_or(fallback)
        })
        .collect()
}

/// The direction a pinhole camera's pixel looks in: A · (u, v, 1), with u and v the pixel's
/// centre as a fraction of the image.
fn ray_at(a: &DMat3, x: usize, y: usize, width: usize, height: usize) -> Vec3 {
    let pixel = DVec3::new((x as f64 + 0.5) / width as f64, (y as f64 + 0.5) / height as f64, 1.0);
    (*a * pixel).as_vec3()
}

/// Fits A so that A · (u, v, 1) points along each wholly covered pixel's ray, from the camera to
/// its position: the smallest eigenvector of the normal equations of d × A·x = 0, over an even
/// subsample of those pixels. (At edges a filtered position is a mix of the surface's and the
/// background's, and would pull the fit.) None with too few pixels or a degenerate fit.
fn fit_rays(camera: Vec3, positions: &[Vec3], coverage: &[f32], width: usize, height: usize) -> Option<DMat3> {
    let samples: Vec<usize> = (0..positions.len()).filter(|&i| coverage[i] >= 0.999).collect();
    if samples.len() < 16 {
        return None;
    }
    let step = (samples.len() / 4096).max(1);
    let mut normal = [[0.0f64; 9]; 9];
    for &i in samples.iter().step_by(step) {
        let Some(d) = (positions[i] - camera).try_normalize().map(|d| d.as_dvec3()) else { continue };
        let x = [(i % width) as f64 + 0.5, (i / width) as f64 + 0.5, 1.0];
        let x = [x[0] / width as f64, x[1] / height as f64, 1.0];
        // Rows of the cross product d × (A x), as coefficients of A's entries, row-major.
        let mut rows = [[0.0f64; 9]; 3];
        for c in 0..3 {
            rows[0][6 + c] = d.y * x[c];
            rows[0][3 + c] = -d.z * x[c];
            rows[1][c] = d.z * x[c];
            rows[1][6 + c] = -d.x * x[c];
            rows[2][3 + c] = d.x * x[c];
            rows[2][c] = -d.y * x[c];
        }
        for row in rows {
            for r in 0..9 {
                for c in 0..9 {
                    normal[r][c] += row[r] * row[c];
                }
            }
        }
    }
    let a = smallest_eigenvector(normal)?;
    let mut matrix = DMat3::from_cols_array(&a).transpose();
    // The fit has no sign: make the rays point from the camera into the scene.
    let i = samples[samples.len() / 2];
    let d = (positions[i] - camera).as_dvec3();
    if ray_at(&matrix, i % width, i / width, width, height).as_dvec3().dot(d) < 0.0 {
        matrix = -matrix;
    }
    matrix.is_finite().then_some(matrix)
}

/// The eigenvector of the smallest eigenvalue of a symmetric 9×9 matrix, by cyclic Jacobi
/// rotations.
fn smallest_eigenvector(mut m: [[f64; 9]; 9]) -> Option<[f64; 9]> {
    let mut vectors = [[0.0f64; 9]; 9];
    for (i, row) in vectors.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for _ in 0..100 {
        let off: f64 = (0..9)
            .flat_map(|p| (0..9).filter(move |&q| q != p).map(move |q| (p, q)))
            .map(|(p, q)| m[p][q] * m[p][q])
            .sum();
        if off < 1e-30 {
            break;
        }
        for p in 0..9 {
            for q in p + 1..9 {
                if m[p][q].abs() < 1e-300 {
                    continue;
                }
                let theta = (m[q][q] - m[p][p]) / (2.0 * m[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let (c, s) = (1.0 / (t * t + 1.0).sqrt(), t / (t * t + 1.0).sqrt());
                for row in m.iter_mut() {
                    let (mkp, mkq) = (row[p], row[q]);
                    row[p] = c * mkp - s * mkq;
                    row[q] = s * mkp + c * mkq;
                }
                let (row_p, row_q) = (m[p], m[q]);
                for k in 0..9 {
                    m[p][k] = c * row_p[k] - s * row_q[k];
                    m[q][k] = s * row_p[k] + c * row_q[k];
                }
                for row in vectors.iter_mut() {
                    let (vp, vq) = (row[p], row[q]);
                    row[p] = c * vp - s * vq;
                    row[q] = s * vp + c * vq;
                }
            }
        }
    }
    let smallest = (0..9).min_by(|&a, &b| m[a][a].total_cmp(&m[b][b]))?;
    let v: [f64; 9] = std::array::from_fn(|k| vectors[k][smallest]);
    v.iter().all(|x| x.is_finite()).then_some(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A pinhole at (1, 2, 8) looking at the origin; positions on a plane behind the origin for
    /// the left half of a 40×30 image, background on the right.
    #[test]
    fn view_vectors_point_at_the_camera_and_background_rays_follow_the_pinhole() {
        let eye = Vec3::new(1.0, 2.0, 8.0);
        let forward = (-eye).normalize();
        let right = forward.cross(Vec3::Y).normalize();
        let up = right.cross(forward);
        let (width, height) = (40, 30);
        let ray = |x: usize, y: usize| {
            let u = ((x as f32 + 0.5) / width as f32 - 0.5) * 0.8;
            let v = (0.5 - (y as f32 + 0.5) / height as f32) * 0.6;
            (forward + right * u + up * v).normalize()
        };
        let mut positions = vec![Vec3::ZERO; width * height];
        let mut covered = vec![0.0f32; width * height];
        for y in 0..height {
            for x in 0..width / 2 {
                let d = ray(x, y);
                let t = (-2.0 - eye.z) / d.z; // the plane z = −2
                positions[y * width + x] = eye + d * t;
                covered[y * width + x] = 1.0;
            }
        }
        let camera =
            Camera { position: eye, forward: Some(forward), projection: Projection::Perspective, from: String::new() };
        let v = view_vectors(&camera, &positions, &covered, width, height);
        for y in 0..height {
            for x in 0..width {
                let expected = -ray(x, y);
                let error = v[y * width + x].angle_between(expected).to_degrees();
                assert!(error < 0.05, "pixel ({x}, {y}) is {error}° off");
            }
        }
        let ortho = Camera { projection: Projection::Orthographic, ..camera };
        assert!(view_vectors(&ortho, &positions, &covered, width, height).iter().all(|&v| v == -forward));
    }

    #[test]
    fn the_header_camera_is_read_from_worldtocamera_and_the_note() {
        // A camera at (0, 0, 5) looking down −Z: worldToCamera translates by −5 in z (row vectors).
        let mut matrices = BTreeMap::new();
        matrices.insert(
            "worldToCamera".to_string(),
            [[1., 0., 0., 0.], [0., 1., 0., 0.], [0., 0., 1., 0.], [0., 0., -5., 1.]],
        );
        let camera = from_header(&BTreeMap::new(), &matrices).unwrap().unwrap();
        assert!((camera.position - Vec3::new(0.0, 0.0, 5.0)).length() < 1e-6);
        assert!((camera.forward.unwrap() - -Vec3::Z).length() < 1e-6);
        assert_eq!(camera.projection, Projection::Perspective);
        matrices.insert(
            "worldToNDC".to_string(),
            [[0.5, 0., 0., 0.], [0., 0.5, 0., 0.], [0., 0., 0.1, 0.], [0.5, 0.5, 0., 1.]],
        );
        assert_eq!(from_header(&BTreeMap::new(), &matrices).unwrap().unwrap().projection, Projection::Orthographic);

        let mut text = BTreeMap::new();
        text.insert(
            NOTE_ATTRIBUTE.to_string(),
            "lookdev.camera position=1,-7,2.5 forward=0,1,0 projection=perspective".to_string(),
        );
        let camera = from_header(&text, &BTreeMap::new()).unwrap().unwrap();
        assert_eq!((camera.position, camera.forward), (Vec3::new(1.0, -7.0, 2.5), Some(Vec3::Y)));
        text.insert(NOTE_ATTRIBUTE.to_string(), "lookdev.camera position=1,-7 forward=0,1,0".to_string());
        assert!(from_header(&text, &BTreeMap::new()).unwrap_err().contains("position=1,-7, not three numbers"));
    }
}

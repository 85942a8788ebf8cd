//! The unfolded cube (Vos et al., Radiology 2003): six 90° × 90° pinhole views around the eye,
//! unfolded into a cross of 4 × 3 square cells, so one frame shows every direction once.
//!
//! ```text
//!          +------+
//!          |  UP  |
//!   +------+------+------+------+
//!   | LEFT |FRONT |RIGHT | BACK |
//!   +------+------+------+------+
//!          | DOWN |
//!          +------+
//! ```
//!
//! With the camera's `forward`, `right` and `up`, each face is a pinhole looking along its axis
//! with its own right and up (the direction of increasing column and of decreasing row):
//!
//! | face  | looks along | its right | its up     |
//! |-------|-------------|-----------|------------|
//! | front | `forward`   | `right`   | `up`       |
//! | right | `right`     | −`forward`| `up`       |
//! | back  | −`forward`  | −`right`  | `up`       |
//! | left  | −`right`    | `forward` | `up`       |
//! | up    | `up`        | `right`   | −`forward` |
//! | down  | −`up`       | `right`   | `forward`  |
//!
//! so every edge two cells share in the cross is the edge the two faces share on the cube: the
//! rays run on across it without a jump (the up face's top is behind the eye, the down face's
//! bottom too). The six other cells show no direction: their pixels have no ray. The cross is
//! as large as the image allows, centred: a face is `min(width / 4, height / 3)` pixels square
//! (an image of 4 : 3, e.g. 768 × 576, fills it exactly).

use glam::DVec3;

/// One face of the cube.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Face {
    /// Along the view direction.
    Front,
    /// To the camera's left.
    Left,
    /// To the camera's right.
    Right,
    /// Along the camera's up.
    Up,
    /// Against the camera's up.
    Down,
    /// Behind the eye.
    Back,
}

impl Face {
    /// Every face, in a fixed order.
    pub const ALL: [Face; 6] = [
        Self::Front,
        Self::Left,
        Self::Right,
        Self::Up,
        Self::Down,
        Self::Back,
    ];

    /// The face's label on the image.
    pub fn name(self) -> &'static str {
        match self {
            Self::Front => "front",
            Self::Left => "left",
            Self::Right => "right",
            Self::Up => "up",
            Self::Down => "down",
            Self::Back => "back",
        }
    }

    /// Its cell of the cross: column 0–3, row 0–2.
    fn cell(self) -> (usize, usize) {
        match self {
            Self::Up => (1, 0),
            Self::Left => (0, 1),
            Self::Front => (1, 1),
            Self::Right => (2, 1),
            Self::Back => (3, 1),
            Self::Down => (1, 2),
        }
    }

    /// The face in cell `(column, row)` of the cross, if one is there.
    fn at_cell(column: i64, row: i64) -> Option<Face> {
        let cell = (usize::try_from(column).ok()?, usize::try_from(row).ok()?);
        Self::ALL.into_iter().find(|f| f.cell() == cell)
    }

    /// Its axis, right and up (see the module doc), from the camera's.
    pub fn basis(self, [forward, right, up]: [DVec3; 3]) -> [DVec3; 3] {
        match self {
            Self::Front => [forward, right, up],
            Self::Right => [right, -forward, up],
            Self::Back => [-forward, -right, up],
            Self::Left => [-right, forward, up],
            Self::Up => [up, right, -forward],
            Self::Down => [-up, right, forward],
        }
    }
}

/// Where the cross lies in an image: the edge of a face and the top-left corner of the
/// cross's 4 × 3 box, pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CubeLayout {
    /// A face's edge, pixels.
    pub face_px: f64,
    /// The top-left corner of the cross's box, pixels.
    pub origin: (f64, f64),
}

impl CubeLayout {
    /// The largest centred cross in an image of `width × height` pixels.
    pub fn new([width, height]: [usize; 2]) -> Self {
        let (w, h) = (width as f64, height as f64);
        let face_px = (w / 4.0).min(h / 3.0);
        Self {
            face_px,
            origin: ((w - 4.0 * face_px) / 2.0, (h - 3.0 * face_px) / 2.0),
        }
    }

    /// The top-left corner of `face` in the image, pixels.
    pub fn corner(&self, face: Face) -> (f64, f64) {
        let (column, row) = face.cell();
        (
            self.origin.0 + column as f64 * self.face_px,
            self.origin.1 + row as f64 * self.face_px,
        )
    }

    /// The face at image point `(x, y)` and the point's position on it, each of `(a, b)` in
    /// −1…1 (`a` rightward, `b` upward); `None` in the cross's empty cells and outside it.
    pub fn face_at(&self, x: f64, y: f64) -> Option<(Face, f64, f64)> {
        let (cx, cy) = (
            (x - self.origin.0) / self.face_px,
            (y - self.origin.1) / self.face_px,
        );
        let face = Face::at_cell(cx.floor() as i64, cy.floor() as i64)?;
        Some((
            face,
            2.0 * (cx - cx.floor()) - 1.0,
            1.0 - 2.0 * (cy - cy.floor()),
        ))
    }

    /// The unit direction seen at image point `(x, y)` by a camera with axes `camera`
    /// (forward, right, up), if any.
    pub fn direction(&self, camera: [DVec3; 3], x: f64, y: f64) -> Option<DVec3> {
        let (face, a, b) = self.face_at(x, y)?;
        let [axis, right, up] = face.basis(camera);
        Some((axis + right * a + up * b).normalize())
    }

    /// The image point where direction `d` (not zero) is seen: on the face whose axis is
    /// nearest to it.
    pub fn position(&self, camera: [DVec3; 3], d: DVec3) -> (f64, f64) {
        let face = Face::ALL
            .into_iter()
            .max_by(|f, g| {
                let along = |face: &Face| d.dot(face.basis(camera)[0]);
                along(f).total_cmp(&along(g))
            })
            .unwrap_or(Face::Front);
        let [axis, right, up] = face.basis(camera);
        let along = d.dot(axis);
        let (a, b) = (d.dot(right) / along, d.dot(up) / along);
        let (x0, y0) = self.corner(face);
        (
            x0 + (a + 1.0) / 2.0 * self.face_px,
            y0 + (1.0 - b) / 2.0 * self.face_px,
        )
    }

    /// Distance along unit direction `d` to the near cube `near_mm` from the eye (each face's
    /// near plane), mm.
    pub fn near_along(camera: [DVec3; 3], d: DVec3, near_mm: f64) -> f64 {
        let largest = camera
            .iter()
            .map(|axis| d.dot(*axis).abs())
            .fold(0.0, f64::max);
        near_mm / largest.max(1e-9)
    }
}

//! Indexed triangle meshes in world millimetres, validated once so that tracing never meets a
//! bad index or a NaN.

use glam::DVec3;
use thiserror::Error;

/// Why a list of vertices and faces is not a mesh.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum MeshError {
    /// The mesh has no triangle.
    #[error("the mesh has no triangle")]
    Empty,
    /// A vertex has a NaN or infinite coordinate.
    #[error("vertex {index} has a coordinate that is not finite: {position:?}")]
    NotFinite {
        /// Index of the vertex.
        index: usize,
        /// Its coordinates.
        position: [f64; 3],
    },
    /// A face refers to a vertex that does not exist.
    #[error("face {face} refers to vertex {vertex}, but there are {vertices} vertices")]
    BadIndex {
        /// Index of the face.
        face: usize,
        /// The vertex index it names.
        vertex: u64,
        /// How many vertices there are.
        vertices: usize,
    },
    /// More vertices than 32-bit indices can name.
    #[error("the mesh would have {vertices} vertices, more than 32-bit indices can name")]
    TooLarge {
        /// How many vertices it would have.
        vertices: usize,
    },
}

/// A triangle mesh: world positions (mm, LPS) and triangles as three vertex indices each.
#[derive(Debug, Clone, PartialEq)]
pub struct TriangleMesh {
    vertices: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
}

impl TriangleMesh {
    /// A validated mesh: at least one triangle, every vertex finite, every index in range.
    pub fn new(vertices: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> Result<Self, MeshError> {
        if triangles.is_empty() {
            return Err(MeshError::Empty);
        }
        if let Some(index) = vertices.iter().position(|v| !v.is_finite()) {
            return Err(MeshError::NotFinite {
                index,
                position: vertices[index].to_array(),
            });
        }
        let n = vertices.len();
        for (face, t) in triangles.iter().enumerate() {
            if let Some(&vertex) = t.iter().find(|&&v| v as usize >= n) {
                return Err(MeshError::BadIndex {
                    face,
                    vertex: u64::from(vertex),
                    vertices: n,
                });
            }
        }
        Ok(Self {
            vertices,
            triangles,
        })
    }

    /// The vertices, world mm.
    pub fn vertices(&self) -> &[DVec3] {
        &self.vertices
    }

    /// The triangles, three vertex indices each.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The three corners of triangle `i`.
    pub fn corners(&self, i: usize) -> [DVec3; 3] {
        self.triangles[i].map(|v| self.vertices[v as usize])
    }

    /// The smallest box holding every vertex: (min, max), world mm.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        self.vertices.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), v| (lo.min(*v), hi.max(*v)),
        )
    }

    /// The mesh with every vertex moved by `f` (e.g. from voxel to world space).
    pub fn mapped(mut self, f: impl Fn(DVec3) -> DVec3) -> Result<Self, MeshError> {
        for v in &mut self.vertices {
            *v = f(*v);
        }
        Self::new(self.vertices, self.triangles)
    }

    /// How many edges are not shared by exactly two triangles (0 for a closed, watertight
    /// surface without non-manifold edges).
    pub fn open_edges(&self) -> usize {
        let mut edges: Vec<(u32, u32)> = self
            .triangles
            .iter()
            .flat_map(|&[a, b, c]| [(a, b), (b, c), (c, a)])
            .map(|(a, b)| (a.min(b), a.max(b)))
            .collect();
        edges.sort_unstable();
        let mut open = 0;
        let mut i = 0;
        while i < edges.len() {
            let j = edges[i..].iter().take_while(|&&e| e == edges[i]).count();
            open += usize::from(j != 2);
            i += j;
        }
        open
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tetrahedron() -> TriangleMesh {
        let v = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        TriangleMesh::new(v, vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]).unwrap()
    }

    #[test]
    fn validation_names_the_problem() {
        let v = vec![DVec3::ZERO, DVec3::X, DVec3::Y];
        assert_eq!(TriangleMesh::new(v.clone(), vec![]), Err(MeshError::Empty));
        assert!(matches!(
            TriangleMesh::new(v.clone(), vec![[0, 1, 3]]),
            Err(MeshError::BadIndex {
                face: 0,
                vertex: 3,
                vertices: 3
            })
        ));
        let mut nan = v.clone();
        nan[1].y = f64::NAN;
        assert!(matches!(
            TriangleMesh::new(nan, vec![[0, 1, 2]]),
            Err(MeshError::NotFinite { index: 1, .. })
        ));
    }

    #[test]
    fn a_closed_tetrahedron_has_no_open_edge() {
        let tet = tetrahedron();
        assert_eq!(tet.open_edges(), 0);
        let open = TriangleMesh::new(tet.vertices().to_vec(), tet.triangles()[..3].to_vec());
        assert_eq!(open.unwrap().open_edges(), 3);
        assert_eq!(tet.bounds(), (DVec3::ZERO, DVec3::ONE));
    }
}

//! 3x3 rotation matrices as SOFA builds them (`iauRx`, `iauRy`, `iauRz`, `iauRxr`): a
//! rotation of the frame, applied by premultiplication.

use crate::vector::dot;

/// A 3x3 matrix, row major: `m[i][j]` is row i, column j.
pub type Mat3 = [[f64; 3]; 3];

pub(crate) const IDENTITY: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// a b: the one 3x3 product of the flight binary (the frames' rotations and the
/// controller's attitude chain), kept out of line so that it stays one copy.
#[inline(never)]
pub fn mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut m = [[0.0; 3]; 3];
    for (m_row, a_row) in m.iter_mut().zip(a) {
        for (j, m_ij) in m_row.iter_mut().enumerate() {
            *m_ij = row_dot_column(a_row, b, j);
        }
    }
    m
}

/// The row `r` times `b` (r^T b): the same sums as [`mul`]'s rows.
pub fn row_times(r: &[f64; 3], b: &Mat3) -> [f64; 3] {
    core::array::from_fn(|j| row_dot_column(r, b, j))
}

/// Row `r` times column `j` of `b`, the same sum as [`dot`]. Out of line: inlined, the
/// nine soft-float dot products were most of [`mul`]'s size (docs/target.md, flash),
/// and no controller update multiplies matrices.
#[inline(never)]
fn row_dot_column(r: &[f64; 3], b: &Mat3, j: usize) -> f64 {
    dot(*r, [b[0][j], b[1][j], b[2][j]])
}

/// R1(phi) m: the frame turned by phi about x (`iauRx`).
pub(crate) fn rx(phi: f64, m: &Mat3) -> Mat3 {
    turn(0, phi, m)
}

/// R3(psi) m: the frame turned by psi about z (`iauRz`).
pub(crate) fn rz(psi: f64, m: &Mat3) -> Mat3 {
    turn(2, psi, m)
}

/// The frame turned by phi about axis `k` (0 x, 2 z), premultiplying `m`: rows i and j
/// of the identity, i and j the two axes after `k`, hold (c, s) and (-s, c). One copy
/// for both: the pole and the ATTITUDE frame's C2T each inlined R3, and the
/// precession-nutation matrix R1 twice (docs/target.md, flash).
#[inline(never)]
fn turn(k: usize, phi: f64, m: &Mat3) -> Mat3 {
    let (s, c) = crate::trig_f64::sin_cos(phi);
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    let mut r = IDENTITY;
    r[i][i] = c;
    r[i][j] = s;
    r[j][i] = -s;
    r[j][j] = c;
    mul(&r, m)
}

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
    let col = |j: usize| [b[0][j], b[1][j], b[2][j]];
    let (c0, c1, c2) = (col(0), col(1), col(2));
    let row = |r: [f64; 3]| [dot(r, c0), dot(r, c1), dot(r, c2)];
    [row(a[0]), row(a[1]), row(a[2])]
}

/// R1(phi) m: the frame turned by phi about x (`iauRx`).
pub(crate) fn rx(phi: f64, m: &Mat3) -> Mat3 {
    let (s, c) = crate::trig_f64::sin_cos(phi);
    let r = [[1.0, 0.0, 0.0], [0.0, c, s], [0.0, -s, c]];
    mul(&r, m)
}

/// R3(psi) m: the frame turned by psi about z (`iauRz`).
pub(crate) fn rz(psi: f64, m: &Mat3) -> Mat3 {
    let (s, c) = crate::trig_f64::sin_cos(psi);
    let r = [[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]];
    mul(&r, m)
}

//! The navigation state: where the satellite is and how it moves.

/// ECI state vector (z along the Earth's spin axis).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StateVector {
    pub position_m: [f64; 3],
    pub velocity_mps: [f64; 3],
}

//! Plane vector arithmetic for the tests' own closed forms and the
//! generators: written here, independently of the runtime, so the tests do
//! not check the runtime against itself.

/// A point or vector.
pub type P = [f64; 2];

/// `a − b`.
pub fn sub(a: P, b: P) -> P {
    [a[0] - b[0], a[1] - b[1]]
}

/// `a + b`.
pub fn add(a: P, b: P) -> P {
    [a[0] + b[0], a[1] + b[1]]
}

/// `k·a`.
pub fn scale(a: P, k: f64) -> P {
    [a[0] * k, a[1] * k]
}

/// Dot product.
pub fn dot(a: P, b: P) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// z of the cross product.
pub fn cross(a: P, b: P) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// Length.
pub fn norm(a: P) -> f64 {
    a[0].hypot(a[1])
}

/// Distance.
pub fn dist(a: P, b: P) -> f64 {
    norm(sub(a, b))
}

/// `a` scaled to unit length.
pub fn unit(a: P) -> P {
    scale(a, 1.0 / norm(a))
}

/// `a` turned a quarter turn counter-clockwise.
pub fn perp(a: P) -> P {
    [-a[1], a[0]]
}

/// `v` turned by `angle` radians counter-clockwise.
pub fn rotate(v: P, angle: f64) -> P {
    let (s, c) = angle.sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1]]
}

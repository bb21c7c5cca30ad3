//! The node the BVH walk reads (`bvh.rs`): the build's node (`bvh_build.rs`)
//! with its box in f32, rounded outwards, so that it still holds every
//! point the f64 box holds: 32 bytes instead of 56, so a pair of children
//! is one cache line and a walk reads half the memory.

use super::bvh_build::Node;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Node32 {
    pub lo: [f32; 3],
    pub hi: [f32; 3],
    /// Leaf: the first item; interior: the left child (the right is next).
    pub first: u32,
    /// Items of a leaf; 0 for an interior node.
    pub count: u32,
}

impl Node32 {
    /// `n` with its box rounded outwards to f32 (an empty box, lo above
    /// hi, stays empty).
    pub fn of(n: &Node) -> Node32 {
        Node32 {
            lo: n.lo.map(down),
            hi: n.hi.map(up),
            first: n.first,
            count: n.count,
        }
    }
}

/// The largest f32 at or below `x`.
fn down(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) > x {
        y.next_down()
    } else {
        y
    }
}

/// The smallest f32 at or above `x`.
fn up(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) < x {
        y.next_up()
    } else {
        y
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boxes_are_rounded_outwards() {
        for x in [0.1, -0.1, 1e-30, 3.0, -7.3e5, 1e39, f64::INFINITY] {
            assert!(f64::from(down(x)) <= x && f64::from(up(x)) >= x, "{x}");
        }
        assert_eq!(up(0.5), 0.5);
        assert_eq!(down(0.5), 0.5);
        assert!(f64::from(up(0.1)) - 0.1 < 1e-8);
    }
}

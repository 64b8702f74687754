//! Packet traversal: eight rays through the hierarchy together (Wald et al., "Interactive
//! rendering with coherent ray tracing", 2001), for the packet kernel. A child is entered
//! with the set of lanes whose ray meets its box, tested per lane exactly as the one-ray
//! traversal tests it (the same f32 slab arithmetic as `RayBox` lane by lane, so a lane never enters
//! fewer boxes than alone, and never finds another hit); a leaf is handed to the caller
//! with that set, so that a primitive is tested for all its lanes in one lane call. The
//! per-ray set-up (three divisions per ray) and each box test run eight lanes wide.
//!
//! Lanes visit the union of their nodes: for coherent rays (camera rays, the rays of a
//! small scene) the node work is shared, for incoherent rays in a large mesh a lane may
//! be carried through boxes it misses (it is masked there, never tested against their
//! primitives). docs/performance.md has the measured balance.

use super::{f32_up, Bvh, HI, SLAB_ROUNDING, STACK_SIZE, WIDTH};
use std::mem::MaybeUninit;

/// Rays per packet.
pub const PACKET: usize = 8;

/// A set of lanes, lane `i` in bit `i`.
pub type Lanes = u8;

/// The lanes of `set`, lowest first.
#[inline]
pub fn lanes_of(set: Lanes) -> impl Iterator<Item = usize> {
    let mut left = set;
    std::iter::from_fn(move || {
        (left != 0).then(|| {
            let i = left.trailing_zeros() as usize;
            left &= left - 1;
            i
        })
    })
}

/// The box-test data of eight rays, lane by lane (`RayBox` transposed).
pub struct PacketBox {
    org_near: [[f32; PACKET]; 3],
    org_far: [[f32; PACKET]; 3],
    inv: [[f32; PACKET]; 3],
    /// All bits set where the direction is negative along the axis (the near plane is
    /// then `hi`): a bit mask, so that choosing the planes is a vector blend.
    neg: [[u32; PACKET]; 3],
    scale: [f64; PACKET],
}

impl PacketBox {
    /// The packet of rays with origins `o[axis][lane]` and directions `d[axis][lane]`.
    /// Every lane needs a finite origin and a finite non-zero direction, as for `RayBox`
    /// (callers give the lanes they will not ask about a harmless one). The one-ray
    /// set-up's arithmetic (`RayBox::new`), written branch-free so that it runs eight
    /// lanes wide.
    #[inline(always)]
    pub fn new(o: &[[f64; PACKET]; 3], d: &[[f64; PACKET]; 3]) -> PacketBox {
        let mut scale = [0.0f64; PACKET];
        for i in 0..PACKET {
            scale[i] = d[0][i].abs().max(d[1][i].abs()).max(d[2][i].abs());
        }
        let mut pb = PacketBox {
            org_near: [[0.0; PACKET]; 3],
            org_far: [[0.0; PACKET]; 3],
            inv: [[0.0; PACKET]; 3],
            neg: [[0; PACKET]; 3],
            scale,
        };
        for a in 0..3 {
            for i in 0..PACKET {
                let inv = scale[i] / d[a][i];
                let (up, down) = (f32_directed(o[a][i], true), f32_directed(o[a][i], false));
                let neg = 0u32.wrapping_sub((inv < 0.0) as u32);
                pb.inv[a][i] = inv as f32;
                pb.neg[a][i] = neg;
                pb.org_near[a][i] = blend(neg, down, up);
                pb.org_far[a][i] = blend(neg, up, down);
            }
        }
        pb
    }

    /// The box-test limit of lane `i` for ray distance `t_max`.
    #[inline]
    fn limit(&self, i: usize, t_max: f64) -> f32 {
        f32_up(t_max * self.scale[i])
    }

    /// The lanes of `lanes` whose ray meets child `k`'s box of `node` within their limit,
    /// and each lane's entry distance.
    #[inline(always)]
    fn hits(
        &self,
        node: &super::WideNode,
        k: usize,
        lanes: Lanes,
        limit: &[f32; PACKET],
    ) -> (Lanes, [f32; PACKET]) {
        let mut t0 = [0.0f32; PACKET];
        let mut t1 = *limit;
        for a in 0..3 {
            let (lo, hi) = (node.bounds[a][k], node.bounds[HI + a][k]);
            for i in 0..PACKET {
                let m = self.neg[a][i];
                let (near, far) = (blend(m, hi, lo), blend(m, lo, hi));
                let tn = (near - self.org_near[a][i]) * self.inv[a][i];
                let tf = (far - self.org_far[a][i]) * self.inv[a][i];
                // As in the one-ray test: comparisons that ignore a NaN slab distance.
                t0[i] = if tn > t0[i] { tn } else { t0[i] };
                t1[i] = if tf < t1[i] { tf } else { t1[i] };
            }
        }
        let mut hit = 0;
        for i in 0..PACKET {
            hit |= ((t0[i] <= t1[i] * SLAB_ROUNDING) as Lanes) << i;
        }
        (hit & lanes, t0)
    }
}

/// `x` rounded to f32 upwards (`up`) or downwards: `f32_up`/`f32_down` of the one-ray
/// set-up without branches. The nearest f32 is moved one step where it lies on the wrong
/// side of `x`: away from zero when the step's direction matches its sign, towards zero
/// otherwise, and from ±0 to the smallest subnormal of the step's sign.
#[inline(always)]
fn f32_directed(x: f64, up: bool) -> f32 {
    let f = x as f32;
    let back = f as f64;
    let wrong = if up { back < x } else { back > x };
    let bits = f.to_bits();
    // ±1 in two's complement: +1 where the step moves away from zero.
    let away = (f > 0.0) == up;
    let step = 1u32.wrapping_sub(2 * !away as u32);
    let from_zero = if up { 1 } else { 0x8000_0001 };
    let moved = if f == 0.0 {
        from_zero
    } else {
        bits.wrapping_add(step)
    };
    f32::from_bits(if wrong { moved } else { bits })
}

/// `a` where the mask `m` has its bits set, else `b` (a vector blend).
#[inline(always)]
fn blend(m: u32, a: f32, b: f32) -> f32 {
    f32::from_bits((m & a.to_bits()) | (!m & b.to_bits()))
}

/// A pending child: a wide node (`count == 0`) or a leaf's slots, with the lanes that
/// entered it and their entry distances.
#[derive(Clone, Copy)]
struct PacketEntry {
    index: u32,
    count: u32,
    lanes: Lanes,
    t0: [f32; PACKET],
}

impl PacketEntry {
    /// The smallest entry distance among its lanes: the visiting order.
    #[inline]
    fn key(&self) -> f32 {
        lanes_of(self.lanes).fold(f32::INFINITY, |m, i| m.min(self.t0[i]))
    }
}

impl Bvh {
    /// Closest hits of the rays of `lanes` in `pb`. `test(slot, lanes, t_max)` intersects
    /// the primitive in `slot` with the rays of `lanes` restricted to `(0, t_max[i]]`,
    /// lowers `t_max[i]` for each lane it hits (keeping the hit itself), and returns those
    /// lanes. Children are visited nearest-first by their lanes' smallest entry distance.
    #[inline(always)]
    pub fn closest_hit_packet(
        &self,
        pb: &PacketBox,
        lanes: Lanes,
        t_max: &mut [f64; PACKET],
        mut test: impl FnMut(usize, Lanes, &mut [f64; PACKET]) -> Lanes,
    ) {
        if self.nodes.is_empty() || lanes == 0 {
            return;
        }
        let mut limit: [f32; PACKET] = std::array::from_fn(|i| pb.limit(i, t_max[i]));
        // Uninitialized, as in the one-ray traversal: every read pops an entry pushed.
        let mut stack = [const { MaybeUninit::<PacketEntry>::uninit() }; STACK_SIZE];
        let mut sp = 0;
        let mut cur = PacketEntry {
            index: 0,
            count: 0,
            lanes,
            t0: [0.0; PACKET],
        };
        loop {
            if cur.count == 0 {
                let node = &self.nodes[cur.index as usize];
                let mut sorted = [cur; WIDTH];
                let mut keys = [0.0f32; WIDTH];
                let mut n = 0;
                for k in 0..WIDTH {
                    if node.unused(k) {
                        continue;
                    }
                    let (hit, t0) = pb.hits(node, k, cur.lanes, &limit);
                    if hit == 0 {
                        continue;
                    }
                    let e = PacketEntry {
                        index: node.child[k],
                        count: node.count[k] as u32,
                        lanes: hit,
                        t0,
                    };
                    let key = e.key();
                    // Insertion sort by decreasing key: the nearest child last.
                    let mut i = n;
                    while i > 0 && keys[i - 1] < key {
                        sorted[i] = sorted[i - 1];
                        keys[i] = keys[i - 1];
                        i -= 1;
                    }
                    sorted[i] = e;
                    keys[i] = key;
                    n += 1;
                }
                if n > 0 {
                    for &e in &sorted[..n - 1] {
                        stack[sp].write(e);
                        sp += 1;
                    }
                    cur = sorted[n - 1];
                    continue;
                }
            } else {
                let first = cur.index as usize;
                for slot in first..first + cur.count as usize {
                    for i in lanes_of(test(slot, cur.lanes, t_max)) {
                        limit[i] = pb.limit(i, t_max[i]);
                    }
                }
            }
            // Pop the next pending child that some lane may still find a closer hit in.
            loop {
                if sp == 0 {
                    return;
                }
                sp -= 1;
                // SAFETY: entries 0..sp were written by the pushes above.
                let mut e = unsafe { stack[sp].assume_init() };
                for i in lanes_of(e.lanes) {
                    if !(e.t0[i] <= limit[i] * SLAB_ROUNDING) {
                        e.lanes &= !(1 << i);
                    }
                }
                if e.lanes != 0 {
                    cur = e;
                    break;
                }
            }
        }
    }

    /// Which rays of `lanes` hit anything in `(0, t_max[i]]`. `test(slot, lanes)` returns
    /// the lanes among `lanes` whose ray hits the primitive in `slot`; a lane stops at its
    /// first hit, the traversal when every lane has stopped.
    #[inline(always)]
    pub fn any_hit_packet(
        &self,
        pb: &PacketBox,
        lanes: Lanes,
        t_max: &[f64; PACKET],
        mut test: impl FnMut(usize, Lanes) -> Lanes,
    ) -> Lanes {
        if self.nodes.is_empty() || lanes == 0 {
            return 0;
        }
        let limit: [f32; PACKET] = std::array::from_fn(|i| pb.limit(i, t_max[i]));
        let mut active = lanes;
        let mut stack = [const { MaybeUninit::<PacketEntry>::uninit() }; STACK_SIZE];
        let mut sp = 0;
        let mut cur = PacketEntry {
            index: 0,
            count: 0,
            lanes,
            t0: [0.0; PACKET],
        };
        loop {
            let live = cur.lanes & active;
            if cur.count == 0 {
                let node = &self.nodes[cur.index as usize];
                let mut next: Option<PacketEntry> = None;
                for k in 0..WIDTH {
                    if node.unused(k) {
                        continue;
                    }
                    let (hit, _) = pb.hits(node, k, live, &limit);
                    if hit == 0 {
                        continue;
                    }
                    let e = PacketEntry {
                        index: node.child[k],
                        count: node.count[k] as u32,
                        lanes: hit,
                        t0: [0.0; PACKET],
                    };
                    if let Some(prev) = next.replace(e) {
                        stack[sp].write(prev);
                        sp += 1;
                    }
                }
                if let Some(e) = next {
                    cur = e;
                    continue;
                }
            } else {
                let first = cur.index as usize;
                for slot in first..first + cur.count as usize {
                    let live = cur.lanes & active;
                    if live == 0 {
                        break;
                    }
                    active &= !test(slot, live);
                    if active == 0 {
                        return lanes;
                    }
                }
            }
            loop {
                if sp == 0 {
                    return lanes & !active;
                }
                sp -= 1;
                // SAFETY: entries 0..sp were written by the pushes above.
                let e = unsafe { stack[sp].assume_init() };
                if e.lanes & active != 0 {
                    cur = e;
                    break;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{f32_down, f32_up};
    use super::*;

    #[test]
    fn branch_free_rounding_is_the_one_ray_rounding() {
        let mut values = vec![
            0.0, -0.0, 1e-320, -1e-320, 1e-40, -1e-40, 1e30, -1e30, 1e39, -1e39,
        ];
        let mut x = 1.234_567_890_123e-5_f64;
        while x < 1e31 {
            values.extend([x, -x, (x as f32) as f64, -((x as f32) as f64)]);
            x *= 1.37;
        }
        for v in values {
            assert_eq!(
                f32_directed(v, true).to_bits(),
                f32_up(v).to_bits(),
                "{v:e} up"
            );
            assert_eq!(
                f32_directed(v, false).to_bits(),
                f32_down(v).to_bits(),
                "{v:e} down"
            );
        }
    }
}

//! Deep stencil wrap: N front faces (INCR_WRAP) and M back faces (DECR_WRAP) over one 16 x 16
//! tile, in one two-sided state as shadow volumes count, for N and M in the hundreds: the
//! count must come back to exactly `(init + N - M) mod 256` — including exactly 0 when
//! N = M — whatever the order (fronts first, backs first, shuffled within one draw, or every
//! face its own draw in shuffled order), and with a write mask below 0xff the masked bits
//! count modulo their own width while the others keep their initial value.
//!
//! Each face is one triangle whose edges lie outside the tile (no edge passes near a pixel
//! centre, so every pixel is judged), with vertices on the sub-pixel grid.

use super::{stencil_only, two_sided, Rng};
use crate::cases::{pixel_ortho, Case, Config, Draw};

const SIZE: (u32, u32) = (16, 16);

/// One triangle covering the whole tile with its edges outside it: front facing
/// (counter-clockwise in Vulkan's sense under `pixel_ortho`) or back facing.
pub(super) fn cover_tile(front: bool) -> [[f32; 4]; 3] {
    let (a, b, c) = ([-1.0, -1.0, 0.5, 1.0], [-1.0, 40.0, 0.5, 1.0], [40.0, -1.0, 0.5, 1.0]);
    if front {
        [a, b, c]
    } else {
        [a, c, b]
    }
}

/// The face sequence: `n` fronts and `m` backs in the given order (`true` = front).
fn faces(n: usize, m: usize, order: Order, rng: &mut Rng) -> Vec<bool> {
    let mut v: Vec<bool> = match order {
        Order::BacksFirst => [vec![false; m], vec![true; n]].concat(),
        _ => [vec![true; n], vec![false; m]].concat(),
    };
    if matches!(order, Order::Shuffled | Order::SeparateDraws) {
        rng.shuffle(&mut v);
    }
    v
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Order {
    FrontsFirst,
    BacksFirst,
    /// Fronts and backs interleaved at random in one draw.
    Shuffled,
    /// Every face its own draw call, in random order.
    SeparateDraws,
}

impl Order {
    fn name(self) -> &'static str {
        match self {
            Order::FrontsFirst => "fronts_first",
            Order::BacksFirst => "backs_first",
            Order::Shuffled => "shuffled",
            Order::SeparateDraws => "separate_draws",
        }
    }
    fn what(self) -> &'static str {
        match self {
            Order::FrontsFirst => "all fronts, then all backs, in one draw",
            Order::BacksFirst => "all backs, then all fronts, in one draw",
            Order::Shuffled => "interleaved in a seeded random order in one draw",
            Order::SeparateDraws => "each face its own draw call, in a seeded random order",
        }
    }
}

/// One case: `n` fronts and `m` backs over a tile starting at `init`, write mask `wm` on both faces.
fn case(config: Config, n: usize, m: usize, order: Order, init: u8, wm: u8, seed: u64) -> Case {
    let mask = if wm == 0xff { String::new() } else { format!(".init_{init:02x}.write_mask_{wm:02x}") };
    let rest = format!("deep.{}.front_{n}.back_{m}{mask}", order.name());
    let mut c = Case::new(config, "wrap", &rest, SIZE, 1.0, init);
    let mut st = two_sided();
    st.0.write_mask = wm as u32;
    st.1.write_mask = wm as u32;
    let state = stencil_only(st);
    let ortho = pixel_ortho(SIZE.0, SIZE.1);
    let seq = faces(n, m, order, &mut Rng::new(seed));
    if order == Order::SeparateDraws {
        for &f in &seq {
            c.draws.push(Draw { state, mvp: ortho, vertices: cover_tile(f).to_vec(), query: false });
        }
    } else {
        let vertices = seq.iter().flat_map(|&f| cover_tile(f)).collect();
        c.draws.push(Draw { state, mvp: ortho, vertices, query: false });
    }
    let expected = if wm == 0xff {
        format!("({init} + {n} - {m}) mod 256 = {}", (init as i64 + n as i64 - m as i64).rem_euclid(256))
    } else {
        format!("the bits of write mask 0x{wm:02x} counting from 0x{init:02x}, the others kept")
    };
    c.what =
        format!("{n} front faces (INCR_WRAP) and {m} back faces (DECR_WRAP) over the whole tile, two-sided, {}: {expected}", order.what());
    c.check_depth = false;
    c
}

/// The deep-wrap cases of `config`.
pub fn cases(config: Config) -> Vec<Case> {
    let mut v = Vec::new();
    let pairs = [(255, 0), (256, 0), (257, 0), (511, 0), (0, 257), (300, 300), (600, 600), (600, 301), (257, 511)];
    for (n, m) in pairs {
        v.push(case(config, n, m, Order::FrontsFirst, 0, 0xff, 0));
    }
    for (n, m) in [(300, 300), (257, 600)] {
        v.push(case(config, n, m, Order::BacksFirst, 0, 0xff, 0));
    }
    v.push(case(config, 600, 300, Order::Shuffled, 0, 0xff, 1));
    v.push(case(config, 511, 511, Order::Shuffled, 0, 0xff, 2));
    v.push(case(config, 300, 257, Order::SeparateDraws, 0, 0xff, 3));
    // Write masks: the low 6 bits count mod 64 (0xa5: the high bits 0x80 kept); the low
    // nibble counts mod 16 over a non-zero start; with the low nibble all ones, a 0xf0 mask
    // makes every increment carry into the high nibble while decrements change nothing.
    v.push(case(config, 300, 0, Order::FrontsFirst, 0xa5, 0x3f, 0));
    v.push(case(config, 600, 301, Order::Shuffled, 0x5a, 0x0f, 4));
    v.push(case(config, 300, 7, Order::Shuffled, 0x0f, 0xf0, 5));
    v
}

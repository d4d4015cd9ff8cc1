//! The lanes' state, constants and contact modes, and their RK4 step: the
//! compact path's fixed RK4 ([`crate::kernel::compact`]) specialised to the
//! two-mass preset, term for term in its order (see the module above).

// Lane loops index several arrays by the same lane, which is what vectorises.
#![allow(clippy::needless_range_loop)]

use super::LANES;
use crate::kernel::compact::LaneLaw;
use crate::methods::tableau::{RK4_A, RK4_B};
use crate::model::impact_damper::State;

/// One value per lane.
pub(super) type V = [f64; LANES];

/// A quantity of every lane's state `(w, w', y, y')`: the state itself, or
/// its rate (a stage's slopes).
#[derive(Clone, Copy)]
pub(super) struct Quad {
    pub(super) w: V,
    pub(super) wv: V,
    pub(super) y: V,
    pub(super) yv: V,
}

impl Quad {
    /// Lane `l`'s state.
    #[inline(always)]
    pub(super) fn lane(&self, l: usize) -> State {
        State {
            main_displacement: self.w[l],
            main_velocity: self.wv[l],
            impact_displacement: self.y[l],
            impact_velocity: self.yv[l],
        }
    }

    /// Lane `l` set to `s`.
    #[inline(always)]
    pub(super) fn set(&mut self, l: usize, s: &State) {
        self.w[l] = s.main_displacement;
        self.wv[l] = s.main_velocity;
        self.y[l] = s.impact_displacement;
        self.yv[l] = s.impact_velocity;
    }

    /// `self + h k`, lane by lane (the compact step's stage points).
    #[inline(always)]
    fn offset(&self, h: f64, k: &Quad) -> Quad {
        let mut out = *self;
        for l in 0..LANES {
            out.w[l] = self.w[l] + h * k.w[l];
            out.wv[l] = self.wv[l] + h * k.wv[l];
            out.y[l] = self.y[l] + h * k.y[l];
            out.yv[l] = self.yv[l] + h * k.yv[l];
        }
        out
    }
}

/// The lanes' state, constants (read from each member's assembly, the
/// compact path's values) and contact modes, structure of arrays. The
/// coordinates are the preset's `[w, y]`; wall 0 is the one `y - w` closes
/// from above (`h . x < 0` there), wall 1 its mirror.
#[derive(Clone, Copy)]
pub(super) struct Lanes<L: LaneLaw> {
    pub(super) state: Quad,
    /// The mode's `M^-1 K` and `M^-1 C`.
    pub(super) stiffness: V,
    pub(super) damping: V,
    /// Wall 0's row over `(w, y)` (wall 1's is its negation).
    pub(super) h: [V; 2],
    pub(super) offset: [V; 2],
    /// Each wall's `M^-1 h^T` over `(w, y)`.
    pub(super) push: [[V; 2]; 2],
    /// The law's parameters ([`LaneLaw::parts`]) and the contact damper.
    pub(super) parts: [V; 2],
    pub(super) contact_damping: V,
    /// Each wall's mode: 1 in compliant contact (its force acts where
    /// indented), 0 open; its latched approach rate and the law's factor.
    pub(super) active: [V; 2],
    pub(super) approach: [V; 2],
    pub(super) factor: [V; 2],
    /// Between steps at most one wall is in contact: its mode and
    /// constants, `h . x`'s sign for it (wall 1's products are wall 0's
    /// negated: the sign's product is that negation, exact), for the plain
    /// steps' rates ([`rates_one_wall`]).
    pub(super) one: OneWall,
    pub(super) law: std::marker::PhantomData<L>,
}

/// The wall in contact of each lane (see [`Lanes::one`]).
#[derive(Clone, Copy)]
pub(super) struct OneWall {
    pub(super) active: V,
    pub(super) sign: V,
    pub(super) offset: V,
    pub(super) approach: V,
    pub(super) factor: V,
    pub(super) push: [V; 2],
}

impl<L: LaneLaw> Lanes<L> {
    /// Lane `l`'s wall `w` in compliant contact, latched at `approach`.
    pub(super) fn activate(&mut self, l: usize, w: usize, approach: f64) {
        self.active[w][l] = 1.0;
        self.approach[w][l] = approach;
        // `Compact::rate_factors`'s division (0 for the laws without one).
        self.factor[w][l] = self.parts[1][l] / approach;
        self.sync(l);
    }

    /// Lane `l`'s wall `w` open.
    pub(super) fn deactivate(&mut self, l: usize, w: usize) {
        self.active[w][l] = 0.0;
        self.sync(l);
    }

    /// Lane `l`'s [`OneWall`] from its walls' modes.
    pub(super) fn sync(&mut self, l: usize) {
        let w = usize::from(self.active[0][l] == 0.0 && self.active[1][l] != 0.0);
        let one = &mut self.one;
        one.active[l] = if self.active[0][l] != 0.0 || self.active[1][l] != 0.0 {
            1.0
        } else {
            0.0
        };
        one.sign[l] = if w == 0 { 1.0 } else { -1.0 };
        one.offset[l] = self.offset[w][l];
        one.approach[l] = self.approach[w][l];
        one.factor[l] = self.factor[w][l];
        one.push[0][l] = self.push[w][0][l];
        one.push[1][l] = self.push[w][1][l];
    }

    /// Lane `l`'s gaps and their rates at `s`, as [`Assembly::gaps`] sums
    /// them: `[(g0, r0), (g1, r1)]`.
    #[inline(always)]
    pub(super) fn gaps(&self, l: usize, s: &State) -> [(f64, f64); 2] {
        let (h0, h1) = (self.h[0][l], self.h[1][l]);
        let hx = h0 * s.main_displacement + h1 * s.impact_displacement;
        let hv = h0 * s.main_velocity + h1 * s.impact_velocity;
        [(self.offset[0][l] + hx, hv), (self.offset[1][l] + -hx, -hv)]
    }
}

/// The rates of every lane's state, `(w', w'', y', y'')`, with at most one
/// wall in contact ([`OneWall`]): [`rates_two_walls`] then (an open wall
/// skipped, the other's products `h . x` times its sign), one select fewer.
#[inline(always)]
fn rates_one_wall<L: LaneLaw>(lanes: &Lanes<L>, s: &Quad) -> Quad {
    let mut rate = Quad {
        w: s.wv,
        wv: [0.0; LANES],
        y: s.yv,
        yv: [0.0; LANES],
    };
    let one = &lanes.one;
    for l in 0..LANES {
        let main = (-lanes.damping[l]) * s.wv[l] - lanes.stiffness[l] * s.w[l];
        let hx = lanes.h[0][l] * s.w[l] + lanes.h[1][l] * s.y[l];
        let hv = lanes.h[0][l] * s.wv[l] + lanes.h[1][l] * s.yv[l];
        let (sx, sv) = (one.sign[l] * hx, one.sign[l] * hv);
        let (indentation, speed) = (-(one.offset[l] + sx), -sv);
        let parts = [lanes.parts[0][l], lanes.parts[1][l]];
        let (force, _) = L::force_of(parts, indentation, speed, one.approach[l], one.factor[l]);
        let pressed = one.active[l] != 0.0 && indentation > 0.0;
        let total = if pressed {
            force + lanes.contact_damping[l] * speed
        } else {
            0.0
        };
        let pushes = total != 0.0;
        rate.wv[l] = if pushes {
            main + one.push[0][l] * total
        } else {
            main
        };
        rate.yv[l] = if pushes {
            -0.0 + one.push[1][l] * total
        } else {
            -0.0
        };
    }
    rate
}

/// The rates of every lane's state, `(w', w'', y', y'')`:
/// [`crate::kernel::compact`]'s rates of the preset in the lanes' modes,
/// term for term. Of the two walls only the one on the side `h . x` points
/// to can be indented (the other's gap is then above its clearance), so
/// one force is evaluated, that wall's, and a select stands for the
/// compact rates' branches (an open wall skipped, a wall not indented
/// pushing nothing): the same bits.
#[inline(always)]
fn rates_two_walls<L: LaneLaw>(lanes: &Lanes<L>, s: &Quad) -> Quad {
    let mut rate = Quad {
        w: s.wv,
        wv: [0.0; LANES],
        y: s.yv,
        yv: [0.0; LANES],
    };
    for l in 0..LANES {
        // `elastic` (no inertial load): `(-c) v - k x`.
        let main = (-lanes.damping[l]) * s.wv[l] - lanes.stiffness[l] * s.w[l];
        // `h_dot` of wall 0 (wall 1's are the negations).
        let hx = lanes.h[0][l] * s.w[l] + lanes.h[1][l] * s.y[l];
        let hv = lanes.h[0][l] * s.wv[l] + lanes.h[1][l] * s.yv[l];
        let lower = hx < 0.0;
        let pick = |a: &[V; 2]| if lower { a[0][l] } else { a[1][l] };
        let (sx, sv) = if lower { (hx, hv) } else { (-hx, -hv) };
        let (indentation, speed) = (-(pick(&lanes.offset) + sx), -sv);
        let parts = [lanes.parts[0][l], lanes.parts[1][l]];
        let (force, _) = L::force_of(
            parts,
            indentation,
            speed,
            pick(&lanes.approach),
            pick(&lanes.factor),
        );
        let pressed = pick(&lanes.active) != 0.0 && indentation > 0.0;
        let total = if pressed {
            force + lanes.contact_damping[l] * speed
        } else {
            0.0
        };
        let (p0, p1) = if lower {
            (lanes.push[0][0][l], lanes.push[0][1][l])
        } else {
            (lanes.push[1][0][l], lanes.push[1][1][l])
        };
        let pushes = total != 0.0;
        rate.wv[l] = if pushes { main + p0 * total } else { main };
        // The damper's coordinate: no elastic term (-0.0, the compact
        // rates' `-inertial`), then the push.
        rate.yv[l] = if pushes { -0.0 + p1 * total } else { -0.0 };
    }
    rate
}

/// One RK4 step `dt` of every lane from `s` in the lanes' modes: the
/// compact step's stages and weights, in its order (`ONE`: at most one wall
/// of each lane in contact, as between steps; a step taken again may have
/// two).
#[inline(always)]
pub(super) fn rk4<const ONE: bool, L: LaneLaw>(lanes: &Lanes<L>, s: &Quad, dt: f64) -> Quad {
    let rates = |x: &Quad| {
        if ONE {
            rates_one_wall(lanes, x)
        } else {
            rates_two_walls(lanes, x)
        }
    };
    let hw = [dt * RK4_A[1][0], dt * RK4_A[2][1], dt * RK4_A[3][2]];
    let b = [dt * RK4_B[0], dt * RK4_B[1], dt * RK4_B[2], dt * RK4_B[3]];
    let k0 = rates(s);
    let k1 = rates(&s.offset(hw[0], &k0));
    let k2 = rates(&s.offset(hw[1], &k1));
    let k3 = rates(&s.offset(hw[2], &k2));
    let mut end = *s;
    for l in 0..LANES {
        end.w[l] = s.w[l] + b[0] * k0.w[l] + b[1] * k1.w[l] + b[2] * k2.w[l] + b[3] * k3.w[l];
        end.wv[l] = s.wv[l] + b[0] * k0.wv[l] + b[1] * k1.wv[l] + b[2] * k2.wv[l] + b[3] * k3.wv[l];
        end.y[l] = s.y[l] + b[0] * k0.y[l] + b[1] * k1.y[l] + b[2] * k2.y[l] + b[3] * k3.y[l];
        end.yv[l] = s.yv[l] + b[0] * k0.yv[l] + b[1] * k1.yv[l] + b[2] * k2.yv[l] + b[3] * k3.yv[l];
    }
    end
}

//! A fixed stretch's open contacts carried through its plain steps: their
//! deepest indentation ([`crate::kernel::fixed::deepest`]) and the
//! trapezoidal sum of their dissipated power ([`crate::kernel::fixed::press`]),
//! the power read from the rates the next step makes at the same state
//! where they hold it to the bit: the force evaluated once, not again
//! beside the stages.

use super::stop_rules::WallGaps;
use super::{Compact, CONTACT, MAX_LEN, MAX_WALLS};
use crate::kernel::events::Open;
use crate::kernel::fixed;
use crate::model::assembly::{Assembly, Mode};

impl Compact {
    /// The `open` contacts' last step of `dt` ended at `y` (`first`: the
    /// rates there, where made): each contact's dissipated power at that
    /// end, as [`fixed::press`] takes it, added to its record.
    #[inline(always)]
    pub(super) fn press(
        &self,
        system: &Assembly,
        d: usize,
        open: &mut [Option<Open>],
        (y, len, modes): (&[f64; MAX_LEN], usize, &[Mode]),
        first: Option<&[f64; MAX_LEN]>,
        dt: f64,
    ) {
        for w in 0..self.count.min(MAX_WALLS) {
            if let Some(oc) = open[w].as_mut() {
                match first.and_then(|first| self.dissipation(d, w, y, modes[w], first)) {
                    Some(power) => fixed::pressed(oc, power, dt),
                    None => {
                        // A copy: the state's address stays untaken (in registers).
                        let at = *y;
                        fixed::press(system, w, oc, &at[..len], modes[w], dt)
                    }
                }
            }
        }
    }

    /// Wall `w`'s dissipated power at `y`, the end of a plain step with its
    /// contact open, as [`fixed::press`] evaluates it, read from the rates
    /// `first` made at `y` in `mode` (their loss room: the same law and
    /// sums); None where those rates make no loss of the wall's (not in
    /// compliant contact) or their products may differ from `press`'s in
    /// the last bit: `press` sums a gap's terms in order (`Assembly::gap`),
    /// the rates in two halves (`h_dot`), which is the same sum for two
    /// coordinates or fewer (the two-mass damper). The wall is indented at
    /// `y` (a plain step ends indented exactly where in contact, by the
    /// same sums), so the rates' loss is the law's, not a contact damper's
    /// apart, where `press` would give none.
    #[inline(always)]
    fn dissipation(
        &self,
        d: usize,
        w: usize,
        y: &[f64; MAX_LEN],
        mode: Mode,
        first: &[f64; MAX_LEN],
    ) -> Option<f64> {
        let wall = &self.walls[w];
        if d > 2 || !matches!(mode, Mode::Compliant { .. }) || wall.law.is_none() {
            return None;
        }
        debug_assert!(-(wall.offset + wall.products(d, y).0) > 0.0);
        Some(first[2 * d + CONTACT + w])
    }
}

/// The open contacts' deepest indentations with a plain fixed step of `dt`
/// (the walls' gaps at its start and end); whether any contact is open.
#[inline(always)]
pub(super) fn deepen(
    open: &mut [Option<Open>],
    (start, end): (&WallGaps, &WallGaps),
    dt: f64,
    located: bool,
) -> bool {
    let mut any = false;
    for (w, contact) in open.iter_mut().enumerate() {
        if let Some(oc) = contact.as_mut() {
            fixed::deepest(oc, fixed::indentation_data(start[w], end[w], dt), located);
            any = true;
        }
    }
    any
}

//! The anchors' method, for comparison: the q current recorded at constant speed, binned
//! by the shaft angle (moteus's `cogging_dq_comp`, ODrive's map from the velocity
//! integrator). The log is cut into half-second blocks and those of steady rotation kept;
//! per block the current less its mean is averaged per bin; the blocks turning forward
//! and backward are averaged separately and then together, so a
//! current that follows the motion (friction, a lag) cancels and what is fixed to the
//! angle stays. Bins no sample reached are interpolated between their neighbours.
//!
//! The table holds what the speed loop *did* at the recorded operating point, in the
//! constant channel: the part of the ripple the loop rejected (not what got through as
//! speed ripple), and load-scaled ripples frozen at the recorded load.

use crate::bench_log::BenchLog;
use firmware::compensation::BINS;
use std::f64::consts::TAU;
use std::ops::Range;

/// Length of the blocks the log is cut into to find steady rotation. [s]
const BLOCK_S: f64 = 0.5;
/// Slowest mean speed of a block that counts as rotation. [rad/s]
const MIN_SPEED_RAD_S: f64 = 0.5;
/// Largest speed deviation over a block's mean speed that counts as steady (the ripple
/// being learned is a few per cent). [1]
const STEADINESS: f64 = 0.25;

/// A block of steady rotation: its rows and direction.
struct Block {
    rows: Range<usize>,
    forward: bool,
}

/// The log cut into [`BLOCK_S`] blocks, those of steady rotation kept: every sample within
/// [`STEADINESS`] of the block's mean speed, the mean at least [`MIN_SPEED_RAD_S`].
fn steady_blocks(log: &BenchLog) -> Vec<Block> {
    let t = &log.t_s;
    let w = &log.speed_rad_s;
    let mut out = Vec::new();
    let mut start = 0;
    while start < t.len() {
        let end = t[start..]
            .iter()
            .position(|x| *x >= t[start] + BLOCK_S)
            .map_or(t.len(), |i| start + i);
        if end == t.len() {
            break; // the last, short block is left out
        }
        let mean = w[start..end].iter().sum::<f64>() / (end - start) as f64;
        let steady = mean.abs() >= MIN_SPEED_RAD_S
            && w[start..end]
                .iter()
                .all(|v| (v - mean).abs() <= STEADINESS * mean.abs());
        if steady {
            out.push(Block {
                rows: start..end,
                forward: mean > 0.0,
            });
        }
        start = end;
    }
    out
}

/// Per-bin mean of `iq − its block mean` over the steady blocks of one direction; `None`
/// for a bin no sample reached.
fn direction_map(
    log: &BenchLog,
    theta: &[f64],
    blocks: &[Block],
    forward: bool,
) -> Vec<Option<f64>> {
    let mut sum = vec![0.0; BINS];
    let mut n = vec![0usize; BINS];
    for b in blocks.iter().filter(|b| b.forward == forward) {
        let rows = b.rows.clone();
        let mean = log.iq_a[rows.clone()].iter().sum::<f64>() / rows.len().max(1) as f64;
        for k in rows {
            let th = theta[k].rem_euclid(TAU);
            let bin = ((th / TAU * BINS as f64) as usize).min(BINS - 1);
            sum[bin] += log.iq_a[k] - mean;
            n[bin] += 1;
        }
    }
    sum.iter()
        .zip(&n)
        .map(|(s, c)| (*c > 0).then(|| s / *c as f64))
        .collect()
}

/// Fills the bins without a value by linear interpolation between the nearest filled
/// ones, around the revolution; `None` when no bin has one.
fn fill(map: &[Option<f64>]) -> Option<Vec<f64>> {
    let filled: Vec<usize> = (0..map.len()).filter(|i| map[*i].is_some()).collect();
    let first = *filled.first()?;
    let n = map.len();
    let mut out = vec![0.0; n];
    for (j, &a) in filled.iter().enumerate() {
        let b = filled.get(j + 1).copied().unwrap_or(first + n);
        let (va, vb) = (map[a]?, map[b % n]?);
        for i in a..b {
            out[i % n] = va + (vb - va) * (i - a) as f64 / (b - a) as f64;
        }
    }
    Some(out)
}

/// The histogram's constant channel [A] over the drive's bins, or `None` when the log has
/// no logged angle or no steady rotation.
pub fn constant_channel(log: &BenchLog) -> Option<Vec<f64>> {
    let theta = log.theta_m_rad.as_deref()?;
    let blocks = steady_blocks(log);
    let maps: Vec<Vec<f64>> = [true, false]
        .iter()
        .filter_map(|fw| fill(&direction_map(log, theta, &blocks, *fw)))
        .collect();
    let m = maps.len();
    (m > 0).then(|| {
        (0..BINS)
            .map(|b| maps.iter().map(|v| v[b]).sum::<f64>() / m as f64)
            .collect()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_bins_are_interpolated_around_the_revolution() {
        let mut m = vec![None; 8];
        m[1] = Some(1.0);
        m[5] = Some(5.0);
        let f = fill(&m).unwrap();
        assert_eq!(f, vec![2.0, 1.0, 2.0, 3.0, 4.0, 5.0, 4.0, 3.0]);
        assert!(fill(&[None, None]).is_none());
    }
}

//! Linear phase gridding of long sample series, the time-domain half of `refine`'s line families
//! (`allanite.model.linefit`): a family's DTFT folds the samples onto `m` bins of the unit phase
//! u = frac(ν₁n) (linear interpolation, then an FFT), and its waveform is evaluated back at every
//! sample from those bins. NumPy does each in some eight passes over 10⁶-sample temporaries; here each
//! is one pass. The arithmetic is NumPy's, operation for operation and in the same order (no fused
//! multiply-add), so the numbers are the same: x = u·m, j = ⌊x⌋, w = x − j; a sample p puts p − p·w on
//! bin j and p·w on bin j + 1 (mod m), each bin summed in sample order as `np.bincount` sums.

/// The sample's bins (j, j + 1 mod m, offset by its segment's m bins) and the second bin's weight.
#[inline]
fn bins(u: f64, m: usize, off: usize) -> (usize, usize, f64) {
    let x = u * m as f64;
    let j = (x as usize).min(m - 1); // u < 1: only rounding could reach m
    let w = x - j as f64;
    let j1 = if j + 1 >= m { 0 } else { j + 1 };
    (j + off, j1 + off, w)
}

/// Whether every phase lies in [0, 1) and every segment below `n_seg`, with matching lengths.
fn valid(u: &[f64], m: usize, seg: Option<&[usize]>, n_seg: usize, n: usize) -> bool {
    m > 0
        && u.len() == n
        && u.iter().all(|&v| (0.0..1.0).contains(&v))
        && seg.is_none_or(|s| s.len() == n && s.iter().all(|&k| k < n_seg))
}

/// `parts` (each n samples) gridded onto `n_seg` × `m` bins by their phases `u` (in [0, 1)); `seg`
/// gives each sample's segment (None: one segment). Returns one bin vector per part, or None when the
/// lengths disagree or a phase or segment is out of range.
pub fn phase_bins(
    parts: &[&[f64]],
    u: &[f64],
    m: usize,
    seg: Option<&[usize]>,
    n_seg: usize,
) -> Option<Vec<Vec<f64>>> {
    let n = u.len();
    if parts.iter().any(|p| p.len() != n) || !valid(u, m, seg, n_seg.max(1), n) {
        return None;
    }
    Some(
        parts
            .iter()
            .map(|p| binned(|i| p[i], u, m, seg, n_seg))
            .collect(),
    )
}

/// [`phase_bins`] of the two parts y·Re ph and y·(−Im ph) of the samples `y` heterodyned by the
/// phasors `ph` (n complex, re/im interleaved), without forming them.
pub fn phase_bins_heterodyned(
    y: &[f64],
    ph: &[f64],
    u: &[f64],
    m: usize,
    seg: Option<&[usize]>,
    n_seg: usize,
) -> Option<[Vec<f64>; 2]> {
    let n = u.len();
    if y.len() != n || ph.len() != 2 * n || !valid(u, m, seg, n_seg.max(1), n) {
        return None;
    }
    Some([
        binned(|i| y[i] * ph[2 * i], u, m, seg, n_seg),
        binned(|i| y[i] * -ph[2 * i + 1], u, m, seg, n_seg),
    ])
}

/// The two bincounts of `linefit._binned` of the part `p(i)`, then their sum (arguments checked).
fn binned(
    p: impl Fn(usize) -> f64,
    u: &[f64],
    m: usize,
    seg: Option<&[usize]>,
    n_seg: usize,
) -> Vec<f64> {
    let size = m * n_seg.max(1);
    let (mut lo, mut hi) = (vec![0.0; size], vec![0.0; size]);
    for (i, &ui) in u.iter().enumerate() {
        let off = seg.map_or(0, |s| s[i] * m);
        let (j, j1, w) = bins(ui, m, off);
        let pi = p(i);
        let h = pi * w;
        lo[j] += pi - h;
        hi[j1] += h;
    }
    lo.iter_mut().zip(&hi).for_each(|(a, b)| *a += b);
    lo
}

/// Adds to `out` (n samples) the waveform `wave` (m + 1 complex bins, re/im interleaved, the last the
/// first again) interpolated at the phases `u`, times the phasors `ph` (n complex, interleaved) when
/// given: out_n += Re[(wave_j·(1 − w) + wave_{j+1}·w)·ph_n], or the wave's real part alone without them.
/// Returns false (out untouched) when the lengths disagree or a phase is out of range.
pub fn add_waveform(out: &mut [f64], u: &[f64], wave: &[f64], ph: Option<&[f64]>) -> bool {
    let n = out.len();
    let m = (wave.len() / 2).saturating_sub(1);
    if !wave.len().is_multiple_of(2) || m == 0 || ph.is_some_and(|p| p.len() != 2 * n) {
        return false;
    }
    if !valid(u, m, None, 1, n) {
        return false;
    }
    for (i, (o, &ui)) in out.iter_mut().zip(u).enumerate() {
        let x = ui * m as f64;
        let j = (x as usize).min(m - 1);
        let f = x - j as f64;
        let g = 1.0 - f;
        let re = wave[2 * j] * g + wave[2 * j + 2] * f;
        match ph {
            None => *o += re,
            Some(p) => {
                let im = wave[2 * j + 1] * g + wave[2 * j + 3] * f;
                *o += re * p[2 * i] - im * p[2 * i + 1];
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    fn phases(n: usize, nu: f64) -> Vec<f64> {
        (0..n).map(|k| (k as f64 * nu).fract()).collect()
    }

    #[test]
    fn bins_conserve_each_part_and_put_it_at_its_phase() {
        let u = phases(1000, 0.123_456);
        let y: Vec<f64> = (0..1000).map(|k| ((k * 37) % 11) as f64 - 5.0).collect();
        let out = phase_bins(&[&y], &u, 64, None, 1).unwrap();
        let total: f64 = out[0].iter().sum();
        assert!((total - y.iter().sum::<f64>()).abs() < 1e-9);
        // one sample at phase 0.25 on 8 bins: all of it on bin 2
        let one = phase_bins(&[&[3.0]], &[0.25], 8, None, 1).unwrap();
        assert_eq!(one[0][2], 3.0);
        assert_eq!(one[0].iter().sum::<f64>(), 3.0);
    }

    #[test]
    fn heterodyned_bins_are_the_bins_of_the_products() {
        let u = phases(500, 0.0371);
        let y: Vec<f64> = (0..500).map(|k| ((k * 13) % 7) as f64 - 3.0).collect();
        let ph: Vec<f64> = (0..1000)
            .map(|k| ((k * 5) % 9) as f64 / 9.0 - 0.4)
            .collect();
        let re: Vec<f64> = (0..500).map(|i| y[i] * ph[2 * i]).collect();
        let im: Vec<f64> = (0..500).map(|i| y[i] * -ph[2 * i + 1]).collect();
        let want = phase_bins(&[&re, &im], &u, 32, None, 1).unwrap();
        let got = phase_bins_heterodyned(&y, &ph, &u, 32, None, 1).unwrap();
        assert_eq!(got.to_vec(), want);
        assert!(phase_bins_heterodyned(&y, &ph[1..], &u, 32, None, 1).is_none());
    }

    #[test]
    fn segments_get_their_own_bins() {
        let u = [0.5, 0.5, 0.99];
        let out = phase_bins(&[&[1.0, 2.0, 4.0]], &u, 4, Some(&[0, 1, 1]), 2).unwrap();
        assert_eq!(out[0][2], 1.0); // segment 0, bin 2
        assert_eq!(out[0][4 + 2], 2.0); // segment 1, bin 2
        assert!((out[0][4 + 3] + out[0][4] - 4.0).abs() < 1e-12); // the last bin wraps to the first
        assert!(out[0][4] > 3.8);
    }

    #[test]
    fn waveform_interpolates_linearly_and_takes_the_phasors() {
        let wave = [0.0, 1.0, 2.0, 1.0, 4.0, 1.0, 6.0, 1.0, 0.0, 1.0];
        let mut out = vec![10.0, 0.0];
        assert!(add_waveform(&mut out, &[0.375, 0.5], &wave, None));
        assert_eq!(out, vec![13.0, 4.0]);
        let mut out = vec![0.0];
        assert!(add_waveform(&mut out, &[0.5], &wave, Some(&[0.0, 1.0])));
        assert_eq!(out, vec![-1.0]); // Re[(4 + i)·i]
    }

    #[test]
    fn bad_shapes_and_phases_are_refused() {
        assert!(phase_bins(&[&[1.0]], &[1.0], 4, None, 1).is_none());
        assert!(phase_bins(&[&[1.0, 2.0]], &[0.1], 4, None, 1).is_none());
        assert!(phase_bins(&[&[1.0]], &[0.1], 4, Some(&[2]), 2).is_none());
        assert!(phase_bins(&[&[1.0]], &[f64::NAN], 4, None, 1).is_none());
        let mut out = vec![0.0];
        assert!(!add_waveform(&mut out, &[0.5], &[1.0, 2.0, 3.0], None));
        assert!(!add_waveform(
            &mut out,
            &[-0.1],
            &[1.0, 2.0, 3.0, 4.0],
            None
        ));
        assert!(!add_waveform(
            &mut out,
            &[0.5],
            &[1.0, 2.0, 3.0, 4.0],
            Some(&[1.0])
        ));
    }
}

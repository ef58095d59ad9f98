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
    Some(binned_pair(
        |i| (y[i] * ph[2 * i], y[i] * -ph[2 * i + 1]),
        u,
        m,
        seg,
        n_seg,
    ))
}

/// [`phase_bins_heterodyned`] with the phasors made sample by sample from a [`Lattice`] instead of read
/// from an array of n complex values (the same numbers: see [`Lattice`]).
pub fn phase_bins_lattice(
    y: &[f64],
    ph: &Lattice,
    u: &[f64],
    m: usize,
    seg: Option<&[usize]>,
    n_seg: usize,
) -> Option<[Vec<f64>; 2]> {
    let n = u.len();
    if y.len() != n || !ph.valid(n) || !valid(u, m, seg, n_seg.max(1), n) {
        return None;
    }
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the CPU has the feature the function is compiled for (checked just above).
        return Some(unsafe { lattice_pair_fma(y, ph, u, m, seg, n_seg) });
    }
    Some(lattice_pair(y, ph, u, m, seg, n_seg))
}

/// [`lattice_pair`] compiled with the fused multiply-add instruction (`mul_add` is correctly rounded
/// either way — an instruction instead of a call to libm's `fma`: the same numbers).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "fma")]
unsafe fn lattice_pair_fma(
    y: &[f64],
    ph: &Lattice,
    u: &[f64],
    m: usize,
    seg: Option<&[usize]>,
    n_seg: usize,
) -> [Vec<f64>; 2] {
    lattice_pair(y, ph, u, m, seg, n_seg)
}

#[inline(always)]
fn lattice_pair(
    y: &[f64],
    ph: &Lattice,
    u: &[f64],
    m: usize,
    seg: Option<&[usize]>,
    n_seg: usize,
) -> [Vec<f64>; 2] {
    binned_pair(
        #[inline(always)]
        |i| {
            let (re, im) = ph.at(i);
            (y[i] * re, y[i] * -im)
        },
        u,
        m,
        seg,
        n_seg,
    )
}

/// The phasors e^{i2πaνn} at the sample indices `idx` that `allanite.model.linefit` makes for a line
/// family's second generator ν (`_phasor`, raised to the power a = |s| by `_groups`), made per sample
/// instead of kept as n complex values: index n's block phasor `blocks[⌊n/B⌋ − k0]` times its offset's
/// `offsets[n mod B]` (B = the offsets' count, a power of two; both tables complex, re/im interleaved),
/// that product multiplied in a − 1 more times, conjugated when `conj`. Each complex product is NumPy's
/// on x86-64 (its SIMD loop fuses a multiply-add): x·y = (fma(x.re, y.re, −x.im·y.im),
/// fma(x.re, y.im, x.im·y.re)), the left operand the block's (then the running power's), so the
/// phasors are NumPy's bit for bit there.
pub struct Lattice<'a> {
    pub idx: &'a [i64],
    pub blocks: &'a [f64],
    pub offsets: &'a [f64],
    pub k0: i64,
    pub power: usize,
    pub conj: bool,
}

impl Lattice<'_> {
    /// log2 of the block length B (the offsets' count), or None where it is not a power of two.
    fn shift(&self) -> Option<u32> {
        let b = self.offsets.len() / 2;
        (b.is_power_of_two() && self.offsets.len().is_multiple_of(2)).then(|| b.trailing_zeros())
    }

    /// Whether the tables are whole complex numbers, B a power of two, the power ≥ 1 and every index's
    /// block in the table.
    fn valid(&self, n: usize) -> bool {
        let nb = (self.blocks.len() / 2) as i64;
        let Some(sh) = self.shift() else {
            return false;
        };
        self.idx.len() == n
            && self.power >= 1
            && self.blocks.len().is_multiple_of(2)
            && self
                .idx
                .iter()
                .all(|&k| (0..nb).contains(&((k >> sh) - self.k0)))
    }

    /// The phasor of the i-th index (arguments checked by [`Lattice::valid`]): ⌊n/B⌋ and n mod B as an
    /// arithmetic shift and a mask (B a power of two; the floor and the remainder ≥ 0 of NumPy's `//`, `%`).
    #[inline(always)]
    fn at(&self, i: usize) -> (f64, f64) {
        let b = self.offsets.len() / 2;
        let sh = b.trailing_zeros();
        let k = self.idx[i];
        let j = ((k >> sh) - self.k0) as usize;
        let o = (k & (b as i64 - 1)) as usize;
        let base = cmul(
            (self.blocks[2 * j], self.blocks[2 * j + 1]),
            (self.offsets[2 * o], self.offsets[2 * o + 1]),
        );
        let mut cur = base;
        for _ in 1..self.power {
            cur = cmul(cur, base);
        }
        if self.conj {
            (cur.0, -cur.1)
        } else {
            cur
        }
    }
}

/// NumPy's complex product on x86-64 (see [`Lattice`]).
#[inline(always)]
fn cmul(x: (f64, f64), y: (f64, f64)) -> (f64, f64) {
    (x.0.mul_add(y.0, -(x.1 * y.1)), x.0.mul_add(y.1, x.1 * y.0))
}

/// Two parts `p(i)` gridded in one pass: each part's bins summed in sample order, as [`binned`] sums
/// them one part at a time (so the same numbers).
#[inline(always)]
fn binned_pair(
    p: impl Fn(usize) -> (f64, f64),
    u: &[f64],
    m: usize,
    seg: Option<&[usize]>,
    n_seg: usize,
) -> [Vec<f64>; 2] {
    let size = m * n_seg.max(1);
    let (mut lo0, mut hi0) = (vec![0.0; size], vec![0.0; size]);
    let (mut lo1, mut hi1) = (vec![0.0; size], vec![0.0; size]);
    for (i, &ui) in u.iter().enumerate() {
        let off = seg.map_or(0, |s| s[i] * m);
        let (j, j1, w) = bins(ui, m, off);
        let (p0, p1) = p(i);
        let (h0, h1) = (p0 * w, p1 * w);
        lo0[j] += p0 - h0;
        hi0[j1] += h0;
        lo1[j] += p1 - h1;
        hi1[j1] += h1;
    }
    lo0.iter_mut().zip(&hi0).for_each(|(a, b)| *a += b);
    lo1.iter_mut().zip(&hi1).for_each(|(a, b)| *a += b);
    [lo0, lo1]
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
    if ph.is_some_and(|p| p.len() != 2 * n) {
        return false;
    }
    match ph {
        None => add_wave(out, u, wave, None::<fn(usize) -> (f64, f64)>),
        Some(p) => add_wave(out, u, wave, Some(|i: usize| (p[2 * i], p[2 * i + 1]))),
    }
}

/// [`add_waveform`] with the phasors made sample by sample from a [`Lattice`].
pub fn add_waveform_lattice(out: &mut [f64], u: &[f64], wave: &[f64], ph: &Lattice) -> bool {
    if !ph.valid(out.len()) {
        return false;
    }
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the CPU has the feature the function is compiled for (checked just above).
        return unsafe { lattice_wave_fma(out, u, wave, ph) };
    }
    add_wave(out, u, wave, Some(|i| ph.at(i)))
}

/// [`add_waveform_lattice`]'s pass compiled with the fused multiply-add instruction (the same numbers).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "fma")]
unsafe fn lattice_wave_fma(out: &mut [f64], u: &[f64], wave: &[f64], ph: &Lattice) -> bool {
    add_wave(
        out,
        u,
        wave,
        Some(
            #[inline(always)]
            |i| ph.at(i),
        ),
    )
}

#[inline(always)]
fn add_wave(
    out: &mut [f64],
    u: &[f64],
    wave: &[f64],
    ph: Option<impl Fn(usize) -> (f64, f64)>,
) -> bool {
    let n = out.len();
    let m = (wave.len() / 2).saturating_sub(1);
    if !wave.len().is_multiple_of(2) || m == 0 || !valid(u, m, None, 1, n) {
        return false;
    }
    for (i, (o, &ui)) in out.iter_mut().zip(u).enumerate() {
        let x = ui * m as f64;
        let j = (x as usize).min(m - 1);
        let f = x - j as f64;
        let g = 1.0 - f;
        let re = wave[2 * j] * g + wave[2 * j + 2] * f;
        match &ph {
            None => *o += re,
            Some(p) => {
                let im = wave[2 * j + 1] * g + wave[2 * j + 3] * f;
                let (pr, pi) = p(i);
                *o += re * pr - im * pi;
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
    fn lattice_phasors_are_the_products_of_the_tables_and_their_powers() {
        // indices with a gap, from block 3 on (k0 = 3), B = 4: blocks 3 … 6
        let idx: Vec<i64> = (12..20).chain(22..27).collect();
        let tab = |k: f64, nu: f64| ((k * nu).cos(), (k * nu).sin());
        let blocks: Vec<f64> = (3..7)
            .flat_map(|k| [tab(4.0 * k as f64, 0.3).0, tab(4.0 * k as f64, 0.3).1])
            .collect();
        let offsets: Vec<f64> = (0..4)
            .flat_map(|j| [tab(j as f64, 0.3).0, tab(j as f64, 0.3).1])
            .collect();
        let n = idx.len();
        let u = phases(n, 0.0713);
        let y: Vec<f64> = (0..n).map(|k| ((k * 7) % 5) as f64 - 2.0).collect();
        for (power, conj) in [(1, false), (2, false), (3, true)] {
            let mut ph = Vec::with_capacity(2 * n);
            for &k in &idx {
                let (j, o) = ((k / 4 - 3) as usize, (k % 4) as usize);
                let base = cmul(
                    (blocks[2 * j], blocks[2 * j + 1]),
                    (offsets[2 * o], offsets[2 * o + 1]),
                );
                let mut cur = base;
                for _ in 1..power {
                    cur = cmul(cur, base);
                }
                ph.extend([cur.0, if conj { -cur.1 } else { cur.1 }]);
            }
            let lat = Lattice {
                idx: &idx,
                blocks: &blocks,
                offsets: &offsets,
                k0: 3,
                power,
                conj,
            };
            let want = phase_bins_heterodyned(&y, &ph, &u, 16, None, 1).unwrap();
            assert_eq!(phase_bins_lattice(&y, &lat, &u, 16, None, 1).unwrap(), want);
            let wave: Vec<f64> = (0..34).map(|k| ((k * 3) % 7) as f64 - 3.0).collect();
            let (mut a, mut b) = (vec![1.0; n], vec![1.0; n]);
            assert!(add_waveform(&mut a, &u, &wave, Some(&ph)));
            assert!(add_waveform_lattice(&mut b, &u, &wave, &lat));
            assert_eq!(a, b);
            assert!(a.iter().any(|&v| (v - 1.0).abs() > 0.5)); // the waveform was added
        }
        // refused: an index before the first block, three offsets (not a power of two), power 0
        let early = Lattice {
            idx: &[11],
            blocks: &blocks,
            offsets: &offsets,
            k0: 3,
            power: 1,
            conj: false,
        };
        assert!(phase_bins_lattice(&[1.0], &early, &[0.5], 4, None, 1).is_none());
        let three = Lattice {
            idx: &[12],
            blocks: &blocks,
            offsets: &offsets[..6],
            k0: 3,
            power: 1,
            conj: false,
        };
        assert!(!add_waveform_lattice(
            &mut [0.0],
            &[0.5],
            &[1.0, 0.0, 1.0, 0.0],
            &three
        ));
        let zero = Lattice {
            idx: &[12],
            blocks: &blocks,
            offsets: &offsets,
            k0: 3,
            power: 0,
            conj: false,
        };
        assert!(phase_bins_lattice(&[1.0], &zero, &[0.5], 4, None, 1).is_none());
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

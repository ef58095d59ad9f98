//! A fast reader for the common case of a text log: plain decimal numbers separated by one
//! delimiter character (or whitespace), one row per line.
//!
//! [`parse_decimal_table`] accepts a strict subset of what NumPy's `loadtxt` reads and returns the
//! same numbers bit for bit (both round the decimal string correctly to the nearest f64: Rust's
//! `str::parse` and CPython's `PyOS_string_to_double`). Anything outside that subset — a ragged
//! row, a field that is not a plain decimal number (`nan`, `inf`, hex, quotes, `1_0`), a number
//! that overflows, a byte that is not printable ASCII, a line break other than `\n` / `\r\n` —
//! makes it return `None`, and the caller reads the file the slow way, which finds and names the
//! problem.

use rayon::prelude::*;

/// The values of columns `cols` (sorted, each < `ncols`) of every data line of `buf`, row-major,
/// and the number of rows; `None` when any line is outside the fast path's grammar (see the
/// module's documentation).
///
/// A line's comment (from `#` to its end) is dropped; a line with nothing left is skipped. With a
/// delimiter (`delim` = `Some(b',')`, …), a line holding only blanks is not skipped (NumPy reads
/// it as a field that is not a number), and fields may carry blanks (space, tab) around their
/// number; with `None`, fields are separated by runs of spaces and tabs and a blank line is
/// skipped. Fields outside `cols` are not looked at, as NumPy's `usecols` does not.
pub fn parse_decimal_table(
    buf: &[u8],
    delim: Option<u8>,
    ncols: usize,
    cols: &[usize],
) -> Option<(Vec<f64>, usize)> {
    if ncols == 0 || cols.windows(2).any(|w| w[0] >= w[1]) || cols.iter().any(|&c| c >= ncols) {
        return None;
    }
    if let Some(d) = delim {
        if !(d.is_ascii_graphic() || d == b'\t') || d == b'#' || is_number_byte(d) {
            return None;
        }
    }
    let mut wanted = vec![false; ncols];
    for &c in cols {
        wanted[c] = true;
    }
    let pieces = line_aligned_pieces(buf);
    if pieces.len() == 1 {
        return parse_piece(buf, delim, &wanted, cols.len());
    }
    // the pieces end at line ends: each line is parsed as it would be in one pass, so the values are the same
    let parsed: Vec<Option<(Vec<f64>, usize)>> = pieces
        .par_iter()
        .map(|&(a, b)| parse_piece(&buf[a..b], delim, &wanted, cols.len()))
        .collect();
    let mut values = Vec::with_capacity(parsed.iter().flatten().map(|(v, _)| v.len()).sum());
    let mut rows = 0usize;
    for piece in parsed {
        let (v, r) = piece?;
        values.extend_from_slice(&v);
        rows += r;
    }
    Some((values, rows))
}

/// Bytes of text from which [`parse_decimal_table`] parses pieces of it on several threads.
pub const PARALLEL_BYTES: usize = 1 << 20;

/// `buf` cut into pieces of about `PARALLEL_BYTES / 2` or more, each ending just after a `\n` (the last at
/// `buf`'s end), as (start, end) — one piece for a short text or one thread.
fn line_aligned_pieces(buf: &[u8]) -> Vec<(usize, usize)> {
    let threads = rayon::current_num_threads();
    if buf.len() < PARALLEL_BYTES || threads < 2 {
        return vec![(0, buf.len())];
    }
    let n = (threads * 4).min(buf.len() / (PARALLEL_BYTES / 2)).max(2);
    let mut pieces = Vec::with_capacity(n);
    let mut start = 0usize;
    for k in 1..n {
        let guess = (buf.len() / n * k).max(start);
        let Some(nl) = buf[guess..].iter().position(|&b| b == b'\n') else {
            break;
        };
        let end = guess + nl + 1;
        if end > start {
            pieces.push((start, end));
            start = end;
        }
    }
    if start < buf.len() {
        pieces.push((start, buf.len()));
    }
    pieces
}

/// The rows of `piece` (whole lines): the values of the `wanted` fields and the number of data rows.
fn parse_piece(
    piece: &[u8],
    delim: Option<u8>,
    wanted: &[bool],
    n_wanted: usize,
) -> Option<(Vec<f64>, usize)> {
    let mut values = Vec::with_capacity(n_wanted * (piece.len() / (8 * wanted.len()) + 1));
    let mut rows = 0usize;
    let mut pos = 0usize;
    while pos < piece.len() {
        let (row, next) = match delim {
            Some(d) => delimited_line(piece, pos, d, wanted, &mut values)?,
            None => blank_separated_line(piece, pos, wanted, &mut values)?,
        };
        rows += usize::from(row);
        pos = next;
    }
    Some((values, rows))
}

/// Where the line that holds `pos` ends: (the end of its content, the start of the next line), after a
/// comment's printable ASCII (and tabs); `None` on any other byte or a bare carriage return.
fn line_end(buf: &[u8], mut pos: usize) -> Option<(usize, usize)> {
    let mut content_end = None;
    while pos < buf.len() {
        match buf[pos] {
            b'\n' => return Some((content_end.unwrap_or(pos), pos + 1)),
            b'\r' if pos + 1 == buf.len() || buf[pos + 1] == b'\n' => {
                return Some((
                    content_end.unwrap_or(pos),
                    pos + 1 + usize::from(pos + 1 < buf.len()),
                ));
            }
            b'#' if content_end.is_none() => content_end = Some(pos),
            b'\t' | b' '..=b'~' => {}
            _ => return None,
        }
        pos += 1;
    }
    Some((content_end.unwrap_or(pos), pos))
}

/// One line of `delim`-separated fields from `pos`: (whether it is a data row, the next line's start).
fn delimited_line(
    buf: &[u8],
    pos: usize,
    delim: u8,
    wanted: &[bool],
    values: &mut Vec<f64>,
) -> Option<(bool, usize)> {
    if matches!(buf[pos], b'\n' | b'\r' | b'#') {
        let (content_end, next) = line_end(buf, pos)?;
        // an empty line or a comment line is skipped; a bare carriage return goes to the slow path
        return (content_end == pos).then_some((false, next));
    }
    let mut i = pos;
    let mut k = 0usize; // field
    loop {
        if k >= wanted.len() {
            return None; // more fields than the header
        }
        if wanted[k] {
            let (v, after) = number(buf, i, delim)?;
            values.push(v);
            i = skip_blanks(buf, after, delim);
        } else {
            while i < buf.len() && !matches!(buf[i], b'\n' | b'\r' | b'#') && buf[i] != delim {
                if !(buf[i] == b'\t' || (b' '..=b'~').contains(&buf[i])) {
                    return None;
                }
                i += 1;
            }
        }
        k += 1;
        if i < buf.len() && buf[i] == delim {
            i += 1;
            continue;
        }
        let (content_end, next) = line_end(buf, i)?;
        if content_end != i {
            return None; // a second number in a field, or text after one
        }
        return (k == wanted.len()).then_some((true, next));
    }
}

/// One line of blank-separated fields from `pos` (leading and trailing blanks and blank lines allowed).
fn blank_separated_line(
    buf: &[u8],
    pos: usize,
    wanted: &[bool],
    values: &mut Vec<f64>,
) -> Option<(bool, usize)> {
    let (content_end, next) = line_end(buf, pos)?;
    let line = &buf[pos..content_end];
    let mut k = 0usize;
    for field in line
        .split(|&b| b == b' ' || b == b'\t')
        .filter(|f| !f.is_empty())
    {
        if k >= wanted.len() {
            return None;
        }
        if wanted[k] {
            let (v, after) = number(field, 0, b' ')?;
            if after != field.len() {
                return None;
            }
            values.push(v);
        }
        k += 1;
    }
    if k == 0 {
        return Some((false, next));
    }
    (k == wanted.len()).then_some((true, next))
}

fn is_number_byte(b: u8) -> bool {
    b.is_ascii_digit() || matches!(b, b'+' | b'-' | b'.' | b'e' | b'E')
}

/// Past the spaces and tabs from `i` — but not past the delimiter (a tab).
fn skip_blanks(buf: &[u8], mut i: usize, delim: u8) -> usize {
    while i < buf.len() && (buf[i] == b' ' || buf[i] == b'\t') && buf[i] != delim {
        i += 1;
    }
    i
}

/// Powers of ten exact in f64 (the fast path of correctly rounded decimal conversion).
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// The number `[blanks] [+-]? (digits [. digits?] | . digits) ([eE] [+-]? digits)?` at `buf[i..]` as the
/// nearest finite f64 and where it ends; `None` for anything else (including a number beyond f64's
/// range). A mantissa of at most 2⁵³ with a power of ten of at most 22 is one exact division or
/// multiplication, rounded once (Clinger's fast path); other numbers go to Rust's correctly rounding
/// parser.
fn number(buf: &[u8], i: usize, delim: u8) -> Option<(f64, usize)> {
    let start = skip_blanks(buf, i, delim);
    let mut j = start;
    let negative = buf.get(j) == Some(&b'-');
    j += usize::from(matches!(buf.get(j), Some(b'+' | b'-')));
    let mut mantissa = 0u64;
    let mut n_digits = 0usize; // digits in the mantissa
    let mut frac_digits = 0i64;
    let mut exact = true; // the mantissa fits u64
    let mut seen_dot = false;
    let mut any_digit = false;
    while j < buf.len() {
        let b = buf[j];
        if b.is_ascii_digit() {
            any_digit = true;
            if n_digits < 19 {
                mantissa = mantissa * 10 + u64::from(b - b'0');
                n_digits += usize::from(mantissa != 0);
            } else {
                exact = false;
            }
            frac_digits += i64::from(seen_dot);
        } else if b == b'.' && !seen_dot {
            seen_dot = true;
        } else {
            break;
        }
        j += 1;
    }
    if !any_digit {
        return None;
    }
    let mut exp = 0i64;
    if matches!(buf.get(j), Some(b'e' | b'E')) {
        j += 1;
        let exp_negative = buf.get(j) == Some(&b'-');
        j += usize::from(matches!(buf.get(j), Some(b'+' | b'-')));
        let exp_start = j;
        while j < buf.len() && buf[j].is_ascii_digit() {
            exp = (exp * 10 + i64::from(buf[j] - b'0')).min(1 << 40);
            j += 1;
        }
        if j == exp_start {
            return None;
        }
        if exp_negative {
            exp = -exp;
        }
    }
    let e10 = exp - frac_digits;
    let v = if exact && mantissa <= 1 << 53 && e10.abs() <= 22 {
        let m = mantissa as f64;
        let v = if e10 < 0 {
            m / POW10[(-e10) as usize]
        } else {
            m * POW10[e10 as usize]
        };
        if negative {
            -v
        } else {
            v
        }
    } else {
        // ASCII checked above; Rust's parser rounds correctly, as CPython's does
        std::str::from_utf8(&buf[start..j]).ok()?.parse().ok()?
    };
    v.is_finite().then_some((v, j))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(
        s: &str,
        delim: Option<u8>,
        ncols: usize,
        cols: &[usize],
    ) -> Option<(Vec<f64>, usize)> {
        parse_decimal_table(s.as_bytes(), delim, ncols, cols)
    }

    #[test]
    fn plain_rows_comments_and_crlf() {
        let got = parse(
            "1,2,3\r\n# note\n\n-4.5e1, +.5 ,6.\n7,8,9 # end\n",
            Some(b','),
            3,
            &[0, 1, 2],
        );
        assert_eq!(
            got,
            Some((vec![1.0, 2.0, 3.0, -45.0, 0.5, 6.0, 7.0, 8.0, 9.0], 3))
        );
    }

    #[test]
    fn only_wanted_columns_are_read() {
        let got = parse("1,x,3\n4,,6\n", Some(b','), 3, &[0, 2]);
        assert_eq!(got, Some((vec![1.0, 3.0, 4.0, 6.0], 2)));
    }

    #[test]
    fn whitespace_separated() {
        let got = parse("  1 \t 2\n\n   \n3 4  \n", None, 2, &[0, 1]);
        assert_eq!(got, Some((vec![1.0, 2.0, 3.0, 4.0], 2)));
    }

    #[test]
    fn anything_else_goes_to_the_slow_path() {
        for bad in [
            "1,2\n3\n",     // ragged: too few
            "1,2\n3,4,5\n", // ragged: too many
            "1,nan\n",      // not a plain number
            "1,1e400\n",    // overflow
            "1,0x10\n",     // hex
            "1,1_0\n",      // underscore
            "1,1e\n",       // exponent without digits
            "1,.\n",        // no digits
            "1,2\n  \n",    // a blank line with a delimiter
            "1,2\r3,4\n",   // a bare CR
            "1,\u{b0}\n",   // non-ASCII
            "1,\"2\"\n",    // quotes
        ] {
            assert_eq!(parse(bad, Some(b','), 2, &[0, 1]), None, "{bad:?}");
        }
    }

    #[test]
    fn correctly_rounded() {
        let s =
            "0.1000000000000000055511151231257827021181583404541015625,2.2250738585072011e-308\n";
        let (v, _) = parse(s, Some(b','), 2, &[0, 1]).unwrap();
        assert_eq!(v[0].to_bits(), 0.1f64.to_bits());
        assert_eq!(v[1].to_bits(), 2.225_073_858_507_201e-308_f64.to_bits());
    }

    #[test]
    fn tab_separated_with_padding() {
        let got = parse("1\t 2 \n3\t4\r\n", Some(b'\t'), 2, &[0, 1]);
        assert_eq!(got, Some((vec![1.0, 2.0, 3.0, 4.0], 2)));
        assert_eq!(parse("1\t\t2\n", Some(b'\t'), 2, &[0, 1]), None);
    }

    /// A text long enough to be parsed in pieces on several threads: the values of one pass, bit for bit;
    /// a bad line in any piece sends the whole text to the slow path.
    #[test]
    fn pieces_give_the_values_of_one_pass() {
        let mut s = String::from("# head\r\n");
        let mut x = 0.123_456_789_f64;
        let mut k = 0usize;
        while s.len() < 3 * PARALLEL_BYTES {
            x = (x * 3.7 + 0.31).fract();
            match k % 5 {
                0 => s.push_str(&format!("{x:.9},{},{:e}\r\n", k, -x * 1e-7)),
                1 => s.push_str(&format!("{x},  {} ,{:.3} # c\n", k, x - 0.5)),
                2 => s.push_str("\n# comment, 1,2\n"),
                _ => s.push_str(&format!("{:.17e},{},{x}\n", x * 1e300, k)),
            }
            k += 1;
        }
        let buf = s.as_bytes();
        assert!(line_aligned_pieces(buf).len() > 1 || rayon::current_num_threads() < 2);
        for cols in [&[0usize, 1, 2][..], &[0, 2], &[1]] {
            let mut wanted = vec![false; 3];
            cols.iter().for_each(|&c| wanted[c] = true);
            let one = parse_piece(buf, Some(b','), &wanted, cols.len()).unwrap();
            let got = parse_decimal_table(buf, Some(b','), 3, cols).unwrap();
            assert_eq!(got.1, one.1);
            assert!(got
                .0
                .iter()
                .zip(&one.0)
                .all(|(a, b)| a.to_bits() == b.to_bits()));
            assert_eq!(got.0.len(), one.0.len());
        }
        let pieces = line_aligned_pieces(buf);
        let (a, b) = pieces[pieces.len() / 2];
        assert!(b > a && buf[b - 1] == b'\n' && (a == 0 || buf[a - 1] == b'\n'));
        let mut bad = s.clone().into_bytes();
        let at = bad.len() * 2 / 3;
        let nl = at + bad[at..].iter().position(|&c| c == b'\n').unwrap() + 1;
        bad.splice(nl..nl, b"1,nan,2\n".iter().copied());
        assert_eq!(parse_decimal_table(&bad, Some(b','), 3, &[0, 1, 2]), None);
    }

    #[test]
    fn empty_body_has_no_rows() {
        assert_eq!(parse("# only\n\n", Some(b','), 2, &[0]), Some((vec![], 0)));
    }
}

//! Tabulated spectra in the CSV layout of `../shared/spectra` and `../shared/cie`: a header row,
//! a wavelength column first, then one column per named sample.

use crate::error::Error;

use crate::Grid;
use std::borrow::Cow;

/// A table of spectra sampled at common wavelengths.
#[derive(Debug, Clone, PartialEq)]
pub struct SpectralTable {
    /// Where the table came from (a file name), used in errors and recorded in models.
    pub source: String,
    /// The wavelength of each row, nm: positive and strictly increasing, at least two.
    pub wavelengths: Vec<f64>,
    /// Sample names, one per column after the wavelength column.
    pub names: Vec<String>,
    /// `columns[k][i]` is sample `k` at `wavelengths[i]`.
    pub columns: Vec<Vec<f64>>,
}

impl SpectralTable {
    /// Parses CSV text. `source` names the text in error messages.
    pub fn parse(source: &str, text: &str) -> Result<SpectralTable, Error> {
        let err = |line: usize, msg: String| Error::Csv {
            file: source.to_string(),
            line,
            msg,
        };
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.trim_end_matches('\r')))
            .filter(|(_, l)| !l.trim().is_empty());
        let Some((hline, header)) = lines.next() else {
            return Err(err(
                1,
                "the file is empty; expected a header row `wavelength_nm,<sample>,…`".into(),
            ));
        };
        let header = split_row(header).map_err(|m| err(hline, m))?;
        if header.len() < 2 {
            return Err(err(
                hline,
                "the header has no sample columns; expected `wavelength_nm,<sample>,…`".into(),
            ));
        }
        let names: Vec<String> = header[1..].iter().map(|c| c.to_string()).collect();
        if let Some(i) = names.iter().position(|n| n.trim().is_empty()) {
            return Err(err(hline, format!("column {} has an empty name", i + 2)));
        }
        let mut wavelengths = Vec::new();
        let mut columns = vec![Vec::new(); names.len()];
        for (ln, line) in lines {
            let cells = split_row(line).map_err(|m| err(ln, m))?;
            if cells.len() != header.len() {
                return Err(err(
                    ln,
                    format!(
                        "ragged row: {} cells where the header has {}",
                        cells.len(),
                        header.len()
                    ),
                ));
            }
            let mut values = cells.iter().enumerate().map(|(c, cell)| {
                let column = if c == 0 {
                    &*header[0]
                } else {
                    names[c - 1].as_str()
                };
                match parse_number(cell) {
                    Ok(v) if v.is_finite() => Ok(v),
                    _ => Err(err(
                        ln,
                        format!("'{cell}' in column '{column}' is not a finite number"),
                    )),
                }
            });
            let wl = values.next().expect("row has at least two cells")?;
            if let Some(&prev) = wavelengths.last() {
                if wl == prev {
                    return Err(err(ln, format!("wavelength {wl} nm appears twice")));
                }
                if wl < prev {
                    return Err(err(
                        ln,
                        format!("wavelengths must increase, but {wl} nm follows {prev} nm"),
                    ));
                }
            }
            if wl <= 0.0 {
                return Err(err(ln, format!("wavelength {wl} nm is not positive")));
            }
            wavelengths.push(wl);
            for (col, v) in columns.iter_mut().zip(values) {
                col.push(v?);
            }
        }
        if wavelengths.len() < 2 {
            return Err(err(
                hline,
                "the table needs at least two wavelength rows".into(),
            ));
        }
        Ok(SpectralTable {
            source: source.to_string(),
            wavelengths,
            names,
            columns,
        })
    }

    /// Every sample resampled onto `grid` (see [`Grid::resample`]).
    pub fn resampled(&self, grid: &Grid) -> Result<Vec<Vec<f64>>, Error> {
        self.columns
            .iter()
            .map(|c| grid.resample(&self.source, &self.wavelengths, c))
            .collect()
    }

    /// The table extended to cover `grid` by holding each sample at its first and last
    /// measured values (CIE 015's practice for missing data at the ends of a range), or `None`
    /// when it covers `grid` already.
    pub fn held_to(&self, grid: &Grid) -> Option<SpectralTable> {
        let (&first, &last) = (self.wavelengths.first()?, self.wavelengths.last()?);
        if first <= grid.start && last >= grid.end {
            return None;
        }
        let mut held = self.clone();
        if first > grid.start {
            held.wavelengths.insert(0, grid.start);
            held.columns.iter_mut().for_each(|c| c.insert(0, c[0]));
        }
        if last < grid.end {
            held.wavelengths.push(grid.end);
            held.columns
                .iter_mut()
                .for_each(|c| c.push(c.last().copied().unwrap_or(0.0)));
        }
        Some(held)
    }

    /// One named column, for tables with fixed column names (observers, illuminants).
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|k| self.columns[k].as_slice())
    }
}

/// `cell.parse::<f64>()`, with a fast path for the plain decimals that measured spectra are
/// written in (`0.1333`, `-12.5`): at most 15 digits make an exact integer m, and m / 10^k is one
/// correctly rounded division of two exact values, so the same double as the full parser gives
/// (Clinger 1990). Anything else (exponents, more digits, inf, nan) goes to the full parser.
fn parse_number(cell: &str) -> Result<f64, std::num::ParseFloatError> {
    let bytes = cell.as_bytes();
    let (negative, digits) = match bytes.first() {
        Some(b'-') => (true, &bytes[1..]),
        _ => (false, bytes),
    };
    let (mut mantissa, mut count, mut decimals, mut point) = (0u64, 0, 0usize, false);
    for &b in digits {
        match b {
            // A 16th digit leaves the fast path before m can overflow.
            b'0'..=b'9' if count == 15 => return cell.parse(),
            b'0'..=b'9' => {
                mantissa = mantissa * 10 + u64::from(b - b'0');
                count += 1;
                decimals += usize::from(point);
            }
            b'.' if !point => point = true,
            _ => return cell.parse(),
        }
    }
    if count == 0 {
        return cell.parse();
    }
    // Powers of ten up to 10¹⁵ are exact doubles.
    const POW10: [f64; 16] = [
        1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
    ];
    let value = mantissa as f64 / POW10[decimals];
    Ok(if negative { -value } else { value })
}

/// Splits one CSV row. Cells may be double-quoted (with `""` for a quote inside), so sample
/// names may contain commas.
fn split_row(line: &str) -> Result<Vec<Cow<'_, str>>, String> {
    // Rows of numbers have no quotes: their cells are slices of the line (no copy per cell).
    if !line.contains('"') {
        let mut cells = Vec::new();
        let mut start = 0;
        for (i, &b) in line.as_bytes().iter().enumerate() {
            if b == b',' {
                // A comma is one byte of UTF-8: both ends are character boundaries.
                cells.push(Cow::Borrowed(line[start..i].trim()));
                start = i + 1;
            }
        }
        cells.push(Cow::Borrowed(line[start..].trim()));
        return Ok(cells);
    }
    let mut cells = Vec::new();
    let mut cell = String::new();
    let mut chars = line.chars().peekable();
    let mut quoted = false;
    while let Some(ch) = chars.next() {
        match (quoted, ch) {
            (false, ',') => cells.push(std::mem::take(&mut cell)),
            (false, '"') if cell.trim().is_empty() => {
                cell.clear();
                quoted = true;
            }
            (true, '"') if chars.peek() == Some(&'"') => {
                chars.next();
                cell.push('"');
            }
            (true, '"') => quoted = false,
            (_, c) => cell.push(c),
        }
    }
    if quoted {
        return Err("a quoted cell is not closed".into());
    }
    cells.push(cell);
    Ok(cells
        .into_iter()
        .map(|c| Cow::Owned(c.trim().to_string()))
        .collect())
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_fast_number_parser_gives_the_standard_parsers_doubles() {
        let mut cells: Vec<String> = [
            "0",
            "-0",
            "5.",
            ".5",
            "-.5",
            "0.1333",
            "380",
            "1e3",
            "+1",
            "1.2.3",
            "",
            ".",
            "-",
            "nan",
            "inf",
            "0.30000000000000004",
            "123456789012345",
            "1234567890123456",
            "0.000000000000001",
            "999999999999999.9",
            // More digits than a u64 holds (found by fuzz/run.sh: an overflow, not a wrong value).
            "531.1122222222222222221",
            "-123456789012345678901234567890",
            " 1",
            "1 ",
        ]
        .map(String::from)
        .to_vec();
        // Reproducible decimals of every length and scale, as CSV writers print them.
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        for _ in 0..20000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let digits = (x % 15 + 1) as usize;
            let m = x % 10u64.pow(digits as u32);
            let point = (x >> 20) as usize % (digits + 1);
            let s = format!("{m:0digits$}");
            cells.push(format!(
                "{}{}.{}",
                if x & 1 == 1 { "-" } else { "" },
                &s[..point],
                &s[point..]
            ));
        }
        for cell in &cells {
            let (fast, std) = (parse_number(cell), cell.parse::<f64>());
            match (fast, std) {
                (Ok(a), Ok(b)) => assert_eq!(a.to_bits(), b.to_bits(), "'{cell}'"),
                (Err(_), Err(_)) => {}
                (a, b) => panic!("'{cell}': {a:?} against {b:?}"),
            }
        }
    }

    use super::*;

    fn parse(text: &str) -> Result<SpectralTable, Error> {
        SpectralTable::parse("t.csv", text)
    }

    #[test]
    fn reads_named_columns() {
        let t = parse("wavelength_nm,a,\"b, quoted\"\r\n400,0.1,0.2\r\n410,0.3,0.4\r\n\n").unwrap();
        assert_eq!(t.wavelengths, vec![400.0, 410.0]);
        assert_eq!(t.names, vec!["a", "b, quoted"]);
        assert_eq!(t.columns, vec![vec![0.1, 0.3], vec![0.2, 0.4]]);
        assert_eq!(t.column("b, quoted"), Some(&[0.2, 0.4][..]));
    }

    #[test]
    fn malformed_tables_say_what_and_where() {
        let cases = [
            ("", "empty"),
            ("wavelength_nm\n400\n410\n", "no sample columns"),
            (
                "wavelength_nm,a\n400,0.1\n410\n",
                "line 3: ragged row: 1 cells where the header has 2",
            ),
            (
                "wavelength_nm,a\n400,0.1\n410,x\n",
                "line 3: 'x' in column 'a' is not a finite number",
            ),
            ("wavelength_nm,a\n400,0.1\n410,NaN\n", "not a finite number"),
            (
                "wavelength_nm,a\n400,0.1\n400,0.2\n",
                "line 3: wavelength 400 nm appears twice",
            ),
            (
                "wavelength_nm,a\n410,0.1\n400,0.2\n",
                "must increase, but 400 nm follows 410 nm",
            ),
            ("wavelength_nm,a\n400,0.1\n", "at least two wavelength rows"),
            (
                "wavelength_nm,a,\n400,0.1,1\n410,0.1,1\n",
                "column 3 has an empty name",
            ),
            ("wavelength_nm,\"a\n400,0.1\n", "not closed"),
        ];
        for (text, want) in cases {
            let got = parse(text).unwrap_err().to_string();
            assert!(got.contains(want), "{text:?}: got {got:?}, want {want:?}");
            assert!(got.contains("t.csv"), "{got}");
        }
    }

    #[test]
    fn resampling_refuses_uncovered_bands() {
        let t = parse("wavelength_nm,a\n400,0.1\n700,0.2\n").unwrap();
        assert!(t
            .resampled(&Grid::PAPER)
            .unwrap_err()
            .to_string()
            .contains("does not cover"));
        let g = Grid::new(400.0, 700.0, 100.0).unwrap();
        let r = t.resampled(&g).unwrap();
        assert!((r[0][1] - 0.13333333333333333).abs() < 1e-15);
        assert!(t.held_to(&g).is_none(), "covered: nothing to hold");
    }

    #[test]
    fn a_short_table_is_held_at_its_end_values() {
        let t = parse("wavelength_nm,a\n400,0.1\n550,0.4\n700,0.2\n").unwrap();
        let r = t
            .held_to(&Grid::PAPER)
            .unwrap()
            .resampled(&Grid::PAPER)
            .unwrap();
        // 380–400 nm hold 0.1, 700–730 nm hold 0.2; inside, the measured values.
        assert_eq!(&r[0][..3], &[0.1, 0.1, 0.1]);
        assert_eq!(&r[0][32..], &[0.2; 4]);
        assert_eq!(r[0][17], 0.4);
    }
}

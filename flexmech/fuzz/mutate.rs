//! Mutations of a model file's text: numeric (extreme and special values in
//! place of a number), structural (lines and tables removed, doubled,
//! swapped, labels and kinds changed) and byte-level (bytes flipped,
//! inserted, deleted, the file cut short). Deterministic for a seed.

/// A small deterministic generator (SplitMix64).
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    /// A generator from `seed`.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// A uniform index below `n` (`n > 0`).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n.max(1) as u64) as usize
    }

    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// The kinds of mutation, one per mutant.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A number replaced by an extreme or special value.
    Numeric,
    /// Lines or tables removed, doubled, swapped or re-labelled.
    Structural,
    /// Bytes flipped, inserted or deleted; the file cut short.
    Bytes,
}

/// Values put in place of a number.
const NUMBERS: &[&str] = &[
    "0",
    "-1",
    "-0.0",
    "1e308",
    "-1e308",
    "1e-308",
    "5e-324",
    "nan",
    "inf",
    "-inf",
    "9223372036854775807",
    "-9223372036854775808",
    "18446744073709551615",
    "1e9",
    "1e18",
    "2.5",
    "1e-12",
    "\"1\"",
    "[]",
    "{}",
    "true",
];

/// Words put in place of a string value.
const WORDS: &[&str] = &[
    "",
    "nope.start",
    "strip.99999",
    "all",
    "screw",
    "rigid",
    "revolute",
    "cam",
    "lobe",
    "spherical",
    "newmark",
    "generalized-alpha",
    "arc-length",
    "energy-momentum-paper",
    "static",
    "dynamic",
    "rz",
    "ux",
    "ground",
    "a/b",
    "..",
    "ä",
];

/// Mutates `text` once by a mutation of `kind`.
pub fn mutate(text: &str, kind: Kind, rng: &mut Rng) -> String {
    match kind {
        Kind::Numeric => numeric(text, rng),
        Kind::Structural => structural(text, rng),
        Kind::Bytes => bytes(text, rng),
    }
}

/// Byte ranges of the numeric literals outside comments.
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    let mut in_comment = false;
    let mut in_string = false;
    while i < b.len() {
        let c = b[i];
        if c == b'\n' {
            in_comment = false;
        } else if !in_comment && c == b'"' {
            in_string = !in_string;
        } else if !in_string && c == b'#' {
            in_comment = true;
        }
        let starts = !in_comment
            && !in_string
            && (c.is_ascii_digit() || (c == b'-' && b.get(i + 1).is_some_and(u8::is_ascii_digit)))
            && (i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_'));
        if starts {
            let start = i;
            i += 1;
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b"+-._".contains(&b[i])) {
                i += 1;
            }
            out.push((start, i));
            continue;
        }
        i += 1;
    }
    out
}

fn numeric(text: &str, rng: &mut Rng) -> String {
    let spans = numbers(text);
    if spans.is_empty() {
        return bytes(text, rng);
    }
    let (a, b) = *rng.pick(&spans);
    let value = if rng.below(4) == 0 {
        // A scaled copy of the number: 10^±k times it.
        let x: f64 = text[a..b].replace('_', "").parse().unwrap_or(1.0);
        let k = rng.below(40) as i32 - 20;
        format!("{:e}", x * 10f64.powi(k))
    } else {
        rng.pick(NUMBERS).to_string()
    };
    format!("{}{}{}", &text[..a], value, &text[b..])
}

fn structural(text: &str, rng: &mut Rng) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    if lines.is_empty() {
        return "x".into();
    }
    let n = lines.len();
    match rng.below(8) {
        0 => {
            lines.remove(rng.below(n));
        }
        1 => {
            let i = rng.below(n);
            let line = lines[i].clone();
            lines.insert(rng.below(n + 1), line);
        }
        2 => {
            let (i, j) = (rng.below(n), rng.below(n));
            lines.swap(i, j);
        }
        3 => {
            // A value taken from another line.
            let (i, j) = (rng.below(n), rng.below(n));
            if let (Some((k, _)), Some((_, v))) =
                (lines[i].split_once('='), lines[j].split_once('='))
            {
                lines[i] = format!("{k}={v}");
            }
        }
        4 => {
            // A string value replaced.
            let i = rng.below(n);
            if let Some((k, _)) = lines[i].split_once('=') {
                if lines[i].contains('"') {
                    lines[i] = format!("{k}= \"{}\"", rng.pick(WORDS));
                }
            }
        }
        5 | 6 => {
            // A whole table removed or doubled.
            let headers: Vec<usize> = (0..n).filter(|&i| lines[i].starts_with('[')).collect();
            if !headers.is_empty() {
                let h = *rng.pick(&headers);
                let end = (h + 1..n).find(|&i| lines[i].starts_with('[')).unwrap_or(n);
                let block: Vec<String> = lines[h..end].to_vec();
                if rng.below(2) == 0 {
                    lines.drain(h..end);
                } else {
                    let at = rng.below(lines.len() + 1);
                    for (k, l) in block.into_iter().enumerate() {
                        lines.insert(at + k, l);
                    }
                }
            }
        }
        _ => {
            // A table header turned single/double, or a key renamed.
            let i = rng.below(n);
            let l = &lines[i];
            lines[i] = if let Some(inner) = l.strip_prefix("[[") {
                format!("[{}", inner.replacen("]]", "]", 1))
            } else if let Some(inner) = l.strip_prefix('[') {
                format!("[[{}", inner.replacen(']', "]]", 1))
            } else if let Some((_, v)) = l.split_once('=') {
                format!(
                    "{} ={v}",
                    rng.pick(&["elements", "every", "dt", "t_end", "node", "zzz"])
                )
            } else {
                format!("{l} = 1")
            };
        }
    }
    let mut out = lines.join("\n");
    out.push('\n');
    out
}

fn bytes(text: &str, rng: &mut Rng) -> String {
    let mut b = text.as_bytes().to_vec();
    let n = b.len().max(1);
    match rng.below(4) {
        0 => {
            let i = rng.below(n).min(b.len().saturating_sub(1));
            if !b.is_empty() {
                b[i] = (rng.next_u64() & 0xff) as u8;
            }
        }
        1 => {
            let at = rng.below(n + 1).min(b.len());
            let junk: &[&[u8]] = &[
                b"\0",
                b"\xff\xfe",
                b"[[",
                b"]]",
                b"\"",
                b"=",
                b"\n[",
                b"#",
                b"{",
                b"'''",
            ];
            let j = rng.pick(junk);
            b.splice(at..at, j.iter().copied());
        }
        2 => {
            let a = rng.below(n).min(b.len());
            let len = 1 + rng.below(16);
            b.drain(a..(a + len).min(b.len()));
        }
        _ => {
            b.truncate(rng.below(n));
        }
    }
    String::from_utf8_lossy(&b).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_skip_comments_strings_and_names() {
        let text = "name = \"a1\" # 12\nEA = 1.0e5\nGA = [5.0e4, -3]\nlink2 = 7\n";
        let found: Vec<&str> = numbers(text).iter().map(|&(a, b)| &text[a..b]).collect();
        assert_eq!(found, ["1.0e5", "5.0e4", "-3", "7"]);
    }

    #[test]
    fn mutations_are_deterministic_for_a_seed() {
        let text = "name = \"m\"\n[solver]\ndt = 0.01\nt_end = 1.0\n";
        for kind in [Kind::Numeric, Kind::Structural, Kind::Bytes] {
            let a = mutate(text, kind, &mut Rng::new(7));
            let b = mutate(text, kind, &mut Rng::new(7));
            assert_eq!(a, b);
        }
    }
}

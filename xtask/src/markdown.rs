//! What the commands that write docs share: numbers as the docs print them, markdown
//! tables, and the blocks a command rewrites between a doc's markers.

/// Scientific, two decimals.
pub fn e2(x: f64) -> String {
    format!("{x:.2e}")
}

/// Scientific, two decimals, the sign always written.
pub fn signed(x: f64) -> String {
    if x >= 0.0 {
        format!("+{x:.2e}")
    } else {
        e2(x)
    }
}

/// Two decimals.
pub fn f2(x: f64) -> String {
    format!("{x:.2}")
}

/// Three significant digits, plain or scientific.
pub fn sig(x: f64) -> String {
    if x != 0.0 && (x.abs() < 0.01 || x.abs() >= 1e4) {
        format!("{x:.2e}")
    } else if x.abs() >= 100.0 {
        format!("{x:.0}")
    } else if x.abs() >= 10.0 {
        format!("{x:.1}")
    } else {
        format!("{x:.3}")
    }
}

/// `lo - hi`, each to three significant digits.
pub fn sig_range(lo: f64, hi: f64) -> String {
    format!("{} - {}", sig(lo), sig(hi))
}

/// A markdown table.
pub fn table<R: AsRef<[String]>>(header: &[&str], rows: &[R]) -> String {
    let mut s = format!(
        "| {} |\n|{}\n",
        header.join(" | "),
        "---|".repeat(header.len())
    );
    for r in rows {
        s.push_str(&format!("| {} |\n", r.as_ref().join(" | ")));
    }
    s
}

/// `doc` with the text from `begin` to `end` (markers included) replaced by `block`.
pub fn replace_between(doc: &str, begin: &str, end: &str, block: &str) -> Option<String> {
    let b = doc.find(begin)?;
    let e = doc[b..].find(end)? + b + end.len();
    Some(format!("{}{block}{}", &doc[..b], &doc[e..]))
}

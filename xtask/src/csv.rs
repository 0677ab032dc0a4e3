//! CSV through the `csv` crate: tables read by column name, and documents written with
//! a `#` preamble (what generated them, the units) ahead of the header.
//!
//! Numbers are handed over as text: each caller formats its own (the shortest text that
//! reads back to the same value, or a fixed number of decimals), and quoting is the
//! crate's (only where a field needs it).

use anyhow::{anyhow, bail, Context, Result};

/// A parsed table: the header and the rows, each as the trimmed field texts.
pub struct Table {
    pub header: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

impl Table {
    /// A header line, then rows of any length; blank lines and `#` lines are skipped.
    pub fn parse(text: &str) -> Result<Table> {
        let mut reader = ::csv::ReaderBuilder::new()
            .trim(::csv::Trim::All)
            .flexible(true)
            .comment(Some(b'#'))
            .from_reader(text.as_bytes());
        let record = |r: &::csv::StringRecord| r.iter().map(str::to_string).collect::<Vec<_>>();
        let header = record(reader.headers().context("csv")?);
        if header.is_empty() {
            bail!("empty input: expected a header line");
        }
        let rows = reader
            .records()
            .map(|r| r.map(|r| record(&r)).context("csv"))
            .collect::<Result<_, _>>()?;
        Ok(Table { header, rows })
    }

    /// Index of each wanted column, by name, in any order.
    pub fn columns(&self, wanted: &[&str]) -> Result<Vec<usize>> {
        wanted
            .iter()
            .map(|w| {
                self.header.iter().position(|h| h == w).ok_or_else(|| {
                    anyhow!("missing column `{w}` (header: {})", self.header.join(","))
                })
            })
            .collect()
    }
}

/// What the tests read of a table: a field by row and column name.
#[cfg(test)]
impl Table {
    /// Field `name` of row `row` (0: the first after the header).
    pub fn field(&self, row: usize, name: &str) -> &str {
        &self.rows[row][self.columns(&[name]).unwrap()[0]]
    }

    pub fn num(&self, row: usize, name: &str) -> f64 {
        self.field(row, name).parse().unwrap()
    }
}

/// A CSV document being written: `preamble` (whole `#` lines), the header, the rows.
pub struct Writer(::csv::Writer<Vec<u8>>);

impl Writer {
    pub fn new<H: AsRef<str>>(preamble: &str, header: &[H]) -> Result<Writer> {
        let mut w = Writer(::csv::Writer::from_writer(preamble.as_bytes().to_vec()));
        w.row(header)?;
        Ok(w)
    }

    pub fn row<F: AsRef<str>>(&mut self, fields: &[F]) -> Result<()> {
        self.0
            .write_record(fields.iter().map(|f| f.as_ref()))
            .context("csv")
    }

    pub fn into_bytes(self) -> Result<Vec<u8>> {
        self.0.into_inner().context("csv")
    }

    pub fn into_string(self) -> Result<String> {
        String::from_utf8(self.into_bytes()?).context("csv")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_in_any_order_and_extras_ignored() {
        let t = Table::parse("# made by hand\nb, a ,extra\n1,2,x\n\n3,4,\"y, z\"\n").unwrap();
        assert_eq!(t.columns(&["a", "b"]).unwrap(), vec![1, 0]);
        assert_eq!(t.rows.len(), 2);
        assert_eq!(t.rows[1], vec!["3", "4", "y, z"]);
        assert!(t
            .columns(&["c"])
            .unwrap_err()
            .to_string()
            .contains("missing column `c`"));
        assert!(Table::parse("\n").is_err());
    }

    #[test]
    fn writes_what_it_reads() {
        let mut w = Writer::new("# units: m\n", &["name", "x"]).unwrap();
        w.row(&["plain", "0.1"]).unwrap();
        w.row(&["with, comma", "1e-7"]).unwrap();
        let text = w.into_string().unwrap();
        assert_eq!(
            text,
            "# units: m\nname,x\nplain,0.1\n\"with, comma\",1e-7\n"
        );
        let t = Table::parse(&text).unwrap();
        assert_eq!(t.rows[1], vec!["with, comma", "1e-7"]);
    }
}

//! A minimal CSV reader for numeric case files: a header line, comma-separated fields,
//! no quoting (the case files hold numbers and simple labels only).

/// A parsed table: the header and the rows, each as the trimmed field texts.
pub struct Table {
    pub header: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

impl Table {
    pub fn parse(text: &str) -> Result<Table, String> {
        let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
        let header = lines
            .next()
            .ok_or("empty input: expected a header line")?
            .split(',')
            .map(|s| s.trim().to_string())
            .collect();
        let rows = lines
            .map(|l| l.split(',').map(|s| s.trim().to_string()).collect())
            .collect();
        Ok(Table { header, rows })
    }

    /// Index of each wanted column, by name, in any order.
    pub fn columns(&self, wanted: &[&str]) -> Result<Vec<usize>, String> {
        wanted
            .iter()
            .map(|w| {
                self.header.iter().position(|h| h == w).ok_or_else(|| {
                    format!("missing column `{w}` (header: {})", self.header.join(","))
                })
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_in_any_order_and_extras_ignored() {
        let t = Table::parse("b, a ,extra\n1,2,x\n\n3,4,y\n").unwrap();
        assert_eq!(t.columns(&["a", "b"]).unwrap(), vec![1, 0]);
        assert_eq!(t.rows.len(), 2);
        assert_eq!(t.rows[1], vec!["3", "4", "y"]);
        assert!(t
            .columns(&["c"])
            .unwrap_err()
            .contains("missing column `c`"));
    }
}

//! Every CSV the orchestrator writes, and the one way they are written: rows
//! are `#[derive(Serialize)]` structs whose field names are the columns,
//! written by the csv crate (which quotes what needs quoting), with the numbers
//! printed as Rust prints them. The columns of compare's results.csv are in
//! `results`, those of accuracy's three CSVs in `accuracy`; why.csv's sit with
//! the verdicts they print (`report::why_table`), ulp.csv's with its report
//! (`ulp::report`).

pub mod accuracy;
pub mod results;

/// A CSV's text, with a last line saying that the run was interrupted
/// (`how`: "interrupted by SIGTERM during the sweep") when it was: the rows
/// are the runs that finished, not the whole plan. A comment line after the
/// rows, so that the header and the columns stay as every reader knows them.
pub fn marked(mut text: String, how: Option<&str>) -> String {
    if let Some(how) = how {
        text.push_str(&format!(
            "# {how}: the rows above are the runs that finished\n"
        ));
    }
    text
}

use anyhow::Context;
use serde::{Serialize, Serializer};

/// An f64 as `{}` prints it: the shortest digits that read back, never an
/// exponent. (The csv crate's own float format writes `10.0` and `1e-7`; the
/// committed results and their readers have `10` and `0.0000001`.)
#[derive(Debug, Clone, Copy, Default)]
pub struct Num(pub f64);

impl Serialize for Num {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(&self.0)
    }
}

/// An f64 with D decimals (`{:.D}`).
#[derive(Debug, Clone, Copy)]
pub struct Decimals<const D: usize>(pub f64);

impl<const D: usize> Serialize for Decimals<D> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(&format_args!("{:.*}", D, self.0))
    }
}

/// A status column: "ok", or "failed: " and why.
pub fn status<T>(result: &Result<T, String>) -> String {
    match result {
        Ok(_) => "ok".into(),
        Err(e) => format!("failed: {e}"),
    }
}

/// The CSV text of `rows`: a header line of the field names, then one line
/// per row. The header is there even without rows, because readers find the
/// columns by name; serde only names the fields of a row it writes, so it
/// comes from a default row then.
pub fn to_string<R: Serialize + Default>(
    rows: impl IntoIterator<Item = R>,
) -> anyhow::Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut any = false;
    for row in rows {
        w.serialize(row).context("writing a CSV row")?;
        any = true;
    }
    if !any {
        w.serialize(R::default()).context("writing a CSV header")?;
    }
    let bytes = w.into_inner().context("writing CSV")?;
    let text = String::from_utf8(bytes).context("writing CSV")?;
    Ok(if any {
        text
    } else {
        text.split_inclusive('\n')
            .next()
            .unwrap_or_default()
            .to_string()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Serialize, Default)]
    struct Row<'a> {
        name: &'a str,
        ms: Option<Num>,
        mean: Option<Decimals<3>>,
        n: u64,
    }

    #[test]
    fn numbers_read_as_before_and_text_is_quoted_only_where_needed() {
        let rows = [
            Row {
                name: "plain",
                ms: Some(Num(10.0)),
                mean: Some(Decimals(1.23456)),
                n: 3,
            },
            Row {
                name: "llvmpipe (LLVM 15.0.6, 256 bits), \"quoted\"",
                ms: Some(Num(1e-7)),
                mean: None,
                n: 0,
            },
        ];
        assert_eq!(
            to_string(rows).unwrap(),
            "name,ms,mean,n\nplain,10,1.235,3\n\"llvmpipe (LLVM 15.0.6, 256 bits), \"\"quoted\"\"\",0.0000001,,0\n"
        );
        assert_eq!(to_string(Vec::<Row>::new()).unwrap(), "name,ms,mean,n\n");
    }
}

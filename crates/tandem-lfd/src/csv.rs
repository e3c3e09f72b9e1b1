//! The one CSV tokenizer of tandem: every CSV file the library and the command line read
//! (demonstrations, executions, reference-time logs, correction flags, need files) is
//! split into a header and rows here, with the same rules and the same located errors.
//!
//! Rules: the first non-blank line is the header of column names (each trimmed and
//! stripped of surrounding double quotes; none empty, none repeated). Every further
//! non-blank line is a row of fields split at `,` and trimmed, with exactly as many fields
//! as the header. Blank lines are skipped; line numbers count them (1-based).
//! There is no quoting of fields: tandem's files hold numbers and names without commas.
//! A UTF-8 byte-order mark (BOM, as spreadsheet programs write) before the header is
//! skipped. A header of one column that contains `;` or a tab is a file in another
//! separator: it is refused with [`Error::Separator`], saying how to convert it.

use crate::{Error, Result};

/// One data row: its 1-based line number and its trimmed fields (one per header column).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CsvRow<'a> {
    /// 1-based line number in the file.
    pub line: usize,
    /// The fields, trimmed, one per header column.
    pub fields: Vec<&'a str>,
}

/// A CSV text split into its header and rows (see the module rules).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CsvTable<'a> {
    file: String,
    header_line: usize,
    names: Vec<String>,
    rows: Vec<CsvRow<'a>>,
}

impl<'a> CsvTable<'a> {
    /// Splits `text`; `file` names it in errors.
    ///
    /// # Errors
    /// [`Error::EmptyFile`] without a header line, [`Error::Separator`] for a file separated
    /// by `;` or tabs, [`Error::BadHeader`] for an empty or
    /// repeated column name, [`Error::RaggedRow`] for a row whose field count differs from
    /// the header's; each with the file, the 1-based line and the 1-based column.
    pub fn parse(text: &'a str, file: &str) -> Result<Self> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(k, l)| (k + 1, l))
            .filter(|(_, l)| !l.trim().is_empty());
        let Some((header_line, header)) = lines.next() else {
            return Err(Error::EmptyFile { file: file.into() });
        };
        let names: Vec<String> = header
            .split(',')
            .map(|f| f.trim().trim_matches('"').to_owned())
            .collect();
        if names.len() == 1
            && let Some((sep, name)) = [(';', "semicolons"), ('\t', "tabs")]
                .into_iter()
                .find(|(c, _)| header.contains(*c))
        {
            return Err(Error::Separator {
                file: file.into(),
                line: header_line,
                separator: name,
                columns: header.split(sep).count(),
                decimal_comma: sep == ';'
                    && text
                        .lines()
                        .skip(header_line)
                        .take(3)
                        .any(|l| l.contains(',')),
            });
        }
        let bad_header = |column: usize, why: String| Error::BadHeader {
            file: file.into(),
            line: header_line,
            column,
            why,
        };
        for (j, name) in names.iter().enumerate() {
            if name.is_empty() {
                return Err(bad_header(j + 1, "empty column name".into()));
            }
            if let Some(k) = names[..j].iter().position(|n| n == name) {
                return Err(bad_header(
                    j + 1,
                    format!("column `{name}` repeats column {}", k + 1),
                ));
            }
        }
        let width = names.len();
        let mut rows = Vec::new();
        for (line, row) in lines {
            let fields: Vec<&str> = row.split(',').map(str::trim).collect();
            if fields.len() != width {
                return Err(Error::RaggedRow {
                    file: file.into(),
                    line,
                    column: fields.len().min(width) + 1,
                    expected: width,
                    found: fields.len(),
                });
            }
            rows.push(CsvRow { line, fields });
        }
        Ok(Self {
            file: file.into(),
            header_line,
            names,
            rows,
        })
    }

    /// The file name used in errors.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// 1-based line of the header.
    pub fn header_line(&self) -> usize {
        self.header_line
    }

    /// The column names, in column order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The data rows, in file order.
    pub fn rows(&self) -> &[CsvRow<'a>] {
        &self.rows
    }

    /// 1-based line just after the last row (or after the header when there is none): where
    /// a missing row would have been.
    pub fn end_line(&self) -> usize {
        self.rows.last().map_or(self.header_line, |r| r.line) + 1
    }

    /// Column index of `name`, if present.
    pub fn column(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// The finite number in row `row`, column `column` (0-based indices).
    ///
    /// # Errors
    /// [`Error::NotNumeric`] or [`Error::NonFinite`] naming file, line, column and the
    /// column's name. Panics if `row` or `column` is out of range.
    pub fn number(&self, row: usize, column: usize) -> Result<f64> {
        let CsvRow { line, fields } = &self.rows[row];
        let text = fields[column];
        let parsed = text.parse::<f64>();
        if let Ok(value) = parsed
            && value.is_finite()
        {
            return Ok(value);
        }
        let (file, line, name) = (self.file.clone(), *line, self.names[column].clone());
        let (column, text) = (column + 1, text.to_owned());
        Err(if parsed.is_ok() {
            Error::NonFinite {
                file,
                line,
                column,
                name,
                text,
            }
        } else {
            Error::NotNumeric {
                file,
                line,
                column,
                name,
                text,
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splits_header_and_rows_skipping_blank_lines() {
        let t = CsvTable::parse("\n\"a\", b\n1, 2\n\n3,4\r\n", "f.csv").unwrap();
        assert_eq!(t.names(), ["a", "b"]);
        assert_eq!(t.header_line(), 2);
        assert_eq!(
            t.rows()[0],
            CsvRow {
                line: 3,
                fields: vec!["1", "2"]
            }
        );
        assert_eq!(t.rows()[1].line, 5);
        assert_eq!(t.end_line(), 6);
        assert_eq!(
            (t.number(1, 0).unwrap(), t.number(1, 1).unwrap()),
            (3.0, 4.0)
        );
        assert_eq!(t.column("b"), Some(1));
    }

    #[test]
    fn errors_are_located() {
        let err = |text: &str| CsvTable::parse(text, "f.csv").unwrap_err().to_string();
        assert_eq!(err(" \n"), "f.csv:1:1: empty file");
        assert_eq!(err("a,,b\n"), "f.csv:1:2: bad header: empty column name");
        assert_eq!(
            err("a,b,a\n"),
            "f.csv:1:3: bad header: column `a` repeats column 1"
        );
        assert_eq!(
            err("a,b\n1,2,3\n"),
            "f.csv:2:3: ragged row: expected 2 fields, found 3"
        );
        let t = CsvTable::parse("a,b\n1,x\nnan,2\n", "f.csv").unwrap();
        assert_eq!(
            t.number(0, 1).unwrap_err().to_string(),
            "f.csv:2:2: column `b`: not a number: `x`"
        );
        assert_eq!(
            t.number(1, 0).unwrap_err().to_string(),
            "f.csv:3:1: column `a`: non-finite value `nan`"
        );
    }
}

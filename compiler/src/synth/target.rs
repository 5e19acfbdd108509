//! Target files: rows of numbers, one per target, as CSV — an optional
//! header line (the first line that is not a comment, when one of its
//! fields is not a number), `#` comments (whole lines or after the
//! numbers), blank lines ignored.

/// One row of a target file.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// Its line in the file (1-based).
    pub line: usize,
    /// Its numbers.
    pub values: Vec<f64>,
}

/// Whether the rows of a target file `name`, of `cols` columns, have
/// given timing (the input first) where free timing reads `free` columns
/// (`x,y`: 2), checked against what `--timing` asked (`given`: `Some(true)`
/// given, `Some(false)` free, `None` as the columns say).
pub fn timed(name: &str, given: Option<bool>, cols: usize, free: usize) -> Result<bool, String> {
    let timed = cols == free + 1;
    match given {
        Some(g) if g != timed => Err(format!(
            "{name}: {cols} columns do not fit --timing {}: given timing reads the input first ({} columns here), free timing does not ({free})",
            if g { "given" } else { "free" },
            free + 1
        )),
        _ => Ok(timed),
    }
}

/// Reads a target file `name` holding `text`. Every row must have the same
/// number of columns, one of `columns`; `what` names the columns for the
/// messages ("x,y or input,x,y"). Errors say `name:line:column` and what
/// to write instead.
pub fn read(name: &str, text: &str, columns: &[usize], what: &str) -> Result<Vec<Row>, String> {
    let mut rows: Vec<Row> = Vec::new();
    let mut header_allowed = true;
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let body = raw.split('#').next().unwrap_or("");
        if body.trim().is_empty() {
            continue;
        }
        let mut values = Vec::new();
        let mut bad = None;
        let mut col = 1;
        for field in body.split(',') {
            let t = field.trim();
            let at = col + (field.len() - field.trim_start().len());
            match t.parse::<f64>() {
                Ok(v) if v.is_finite() => values.push(v),
                _ => {
                    bad.get_or_insert((at, t.to_string()));
                }
            }
            col += field.len() + 1;
        }
        if let Some((at, field)) = bad {
            // A header names its columns: none of its fields is a number.
            let words = body.split(',').all(|f| f.trim().parse::<f64>().is_err());
            if header_allowed && rows.is_empty() && words {
                header_allowed = false;
                continue;
            }
            let field = if field.is_empty() {
                "an empty field".to_string()
            } else {
                format!("`{field}`")
            };
            return Err(format!(
                "{name}:{line}:{at}: error: {field} is not a finite number; each line holds {what}, separated by commas (a header line is allowed first, `#` starts a comment)"
            ));
        }
        header_allowed = false;
        if !columns.contains(&values.len()) {
            return Err(format!(
                "{name}:{line}:1: error: {} numbers on this line; each line holds {what}",
                values.len()
            ));
        }
        if let Some(first) = rows.first() {
            if first.values.len() != values.len() {
                return Err(format!(
                    "{name}:{line}:1: error: {} numbers on this line but {} on line {}: every line has the same columns ({what})",
                    values.len(),
                    first.values.len(),
                    first.line
                ));
            }
        }
        rows.push(Row { line, values });
    }
    if rows.is_empty() {
        return Err(format!(
            "{name}: error: no targets in the file; each line holds {what}"
        ));
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_comments_and_blank_lines() {
        let text = "# from a four-bar\nx, y\n\n1, 2 # first\n3,4\n";
        let rows = read("t.csv", text, &[2, 3], "x,y").unwrap();
        assert_eq!(
            rows,
            [
                Row {
                    line: 4,
                    values: vec![1.0, 2.0]
                },
                Row {
                    line: 5,
                    values: vec![3.0, 4.0]
                }
            ]
        );
    }

    #[test]
    fn errors_name_the_line_and_column() {
        let e = read("t.csv", "1,2\n3, abc\n", &[2], "x,y").unwrap_err();
        assert!(
            e.starts_with("t.csv:2:4: error: `abc` is not a finite number"),
            "{e}"
        );
        let e = read("t.csv", "1,2\n3,4,5\n", &[2, 3], "x,y").unwrap_err();
        assert!(e.contains("3 numbers on this line but 2 on line 1"), "{e}");
        let e = read("t.csv", "1\n", &[2, 3], "x,y").unwrap_err();
        assert!(e.contains("t.csv:1:1: error: 1 numbers"), "{e}");
        let e = read("t.csv", "# nothing\n\n", &[2], "x,y").unwrap_err();
        assert!(e.contains("no targets"), "{e}");
        let e = read("t.csv", "x,y\nu,v\n", &[2], "x,y").unwrap_err();
        assert!(e.starts_with("t.csv:2:1: error: `u`"), "{e}");
        let e = read("t.csv", "1,nan\n", &[2], "x,y").unwrap_err();
        assert!(e.contains("`nan` is not a finite number"), "{e}");
    }
}

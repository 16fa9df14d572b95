//! CSV files of a manifest: scalar estimates (`rep,value` or `rep,v0,v1,...`, optionally a
//! `seconds` column) and repetition times (`rep,seconds`). Each repetition `0..reps` appears once.

/// A CSV of per-repetition rows: each repetition's values (in column order) and, when the file has
/// a `seconds` column, its seconds.
#[derive(Debug, PartialEq)]
pub struct RepTable {
    /// Per repetition, the value columns.
    pub values: Vec<Vec<f64>>,
    /// Per repetition, the `seconds` column.
    pub seconds: Option<Vec<f64>>,
}

/// Reads a per-repetition CSV with columns `rep`, then value columns (`value`, or `v0`, `v1`, ...,
/// or `seconds` alone), expecting `reps` rows; `Err` says what is wrong (column or row named).
pub fn read(text: &str, reps: usize) -> Result<RepTable, String> {
    let mut rdr = csv::ReaderBuilder::new().trim(csv::Trim::All).from_reader(text.as_bytes());
    let header: Vec<String> = rdr.headers().map_err(|e| e.to_string())?.iter().map(str::to_string).collect();
    if header.first().map(String::as_str) != Some("rep") {
        return Err("the first column must be `rep`".into());
    }
    let mut value_cols = Vec::new();
    let mut seconds_col = None;
    for (i, name) in header.iter().enumerate().skip(1) {
        let numbered = name.strip_prefix('v').and_then(|d| d.parse::<usize>().ok()) == Some(value_cols.len());
        match name.as_str() {
            "seconds" if seconds_col.is_none() => seconds_col = Some(i),
            "value" => value_cols.push(i),
            _ if numbered => value_cols.push(i),
            _ => return Err(format!("unknown column `{name}` (expected `value`, `v0`, `v1`, ... and `seconds`)")),
        }
    }
    if header.iter().filter(|h| *h == "value").count() > 0 && value_cols.len() > 1 {
        return Err("give one `value` column or numbered `v0`, `v1`, ... columns".into());
    }
    let mut rows: Vec<Option<(Vec<f64>, Option<f64>)>> = vec![None; reps];
    for (n, record) in rdr.records().enumerate() {
        let line = n + 2;
        let record = record.map_err(|e| format!("line {line}: {e}"))?;
        let rep: usize = record
            .get(0)
            .and_then(|r| r.parse().ok())
            .ok_or_else(|| format!("line {line}: column `rep` is not a repetition index"))?;
        let slot = rows
            .get_mut(rep)
            .ok_or_else(|| format!("line {line}: repetition {rep}, the manifest says reps = {reps}"))?;
        if slot.is_some() {
            return Err(format!("line {line}: repetition {rep} appears twice"));
        }
        let number = |col: usize| -> Result<f64, String> {
            let v: f64 = record
                .get(col)
                .and_then(|s| s.parse().ok())
                .ok_or_else(|| format!("line {line}: column `{}` is not a number", header[col]))?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(format!("line {line}: column `{}` is {v}", header[col]))
            }
        };
        let values = value_cols.iter().map(|&c| number(c)).collect::<Result<Vec<_>, _>>()?;
        let seconds = seconds_col.map(number).transpose()?;
        if seconds.is_some_and(|s| s < 0.0) {
            return Err(format!("line {line}: column `seconds` is negative"));
        }
        *slot = Some((values, seconds));
    }
    let missing = rows.iter().position(Option::is_none);
    if let Some(rep) = missing {
        let held = rows.iter().filter(|r| r.is_some()).count();
        return Err(format!("{held} repetitions, the manifest says reps = {reps} (repetition {rep} is missing)"));
    }
    let rows: Vec<(Vec<f64>, Option<f64>)> = rows.into_iter().flatten().collect();
    let seconds = seconds_col.map(|_| rows.iter().map(|r| r.1.unwrap_or(0.0)).collect());
    Ok(RepTable { values: rows.into_iter().map(|r| r.0).collect(), seconds })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_and_seconds_in_any_row_order() {
        let t = read("rep,v0,v1,seconds\n1,3,4,0.5\n0,1,2,0.25\n", 2).unwrap();
        assert_eq!(t.values, vec![vec![1.0, 2.0], vec![3.0, 4.0]]);
        assert_eq!(t.seconds, Some(vec![0.25, 0.5]));
        let s = read("rep,seconds\n0,1\n1,2\n", 2).unwrap();
        assert_eq!((s.values[0].len(), s.seconds), (0, Some(vec![1.0, 2.0])));
    }

    #[test]
    fn missing_repeated_and_non_finite_rows_are_refused() {
        assert!(read("rep,value\n0,1\n", 2).unwrap_err().contains("missing"));
        assert!(read("rep,value\n0,1\n0,2\n", 2).unwrap_err().contains("twice"));
        assert!(read("rep,value\n0,1\n1,NaN\n", 2).unwrap_err().contains("line 3"));
        assert!(read("rep,value\n0,1\n2,1\n", 2).unwrap_err().contains("reps = 2"));
        assert!(read("rep,colour\n0,1\n", 1).unwrap_err().contains("colour"));
        assert!(read("value,rep\n1,0\n", 1).unwrap_err().contains("`rep`"));
    }
}

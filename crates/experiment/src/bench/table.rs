//! Aligned text tables: the benchmarks' output on a terminal.

/// `cells` (the header first) as lines of columns two spaces apart: the columns in `left`
/// left-aligned (names), the others right-aligned (numbers); no trailing spaces.
pub(crate) fn aligned(cells: &[Vec<String>], left: &[usize]) -> String {
    let columns = cells.first().map_or(0, Vec::len);
    let widths: Vec<usize> = (0..columns)
        .map(|i| {
            cells
                .iter()
                .map(|row| row[i].chars().count())
                .max()
                .unwrap_or(0)
        })
        .collect();
    let mut out = String::new();
    for row in cells {
        let line: Vec<String> = row
            .iter()
            .enumerate()
            .map(|(i, c)| {
                if left.contains(&i) {
                    format!("{c:<w$}", w = widths[i])
                } else {
                    format!("{c:>w$}", w = widths[i])
                }
            })
            .collect();
        out += line.join("  ").trim_end();
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn names_left_numbers_right() {
        let cells = vec![
            vec!["accel".to_string(), "ms".to_string()],
            vec!["bvh8".to_string(), "12.5".to_string()],
        ];
        assert_eq!(super::aligned(&cells, &[0]), "accel    ms\nbvh8   12.5\n");
    }
}

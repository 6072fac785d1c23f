//! Generated regions of Markdown files: the commands that measure (`bench`, `albedo`) write their tables between
//! markers, so that every published figure comes from a command and names the machine it ran on.

use std::path::Path;

use super::CliError;

/// The markers around the region `name` ("" for the bench's main table).
pub fn markers(name: &str) -> (String, String) {
    let tag = if name.is_empty() { "sunshade bench".to_string() } else { format!("sunshade {name}") };
    (format!("<!-- {tag}: begin (generated; do not edit by hand) -->"), format!("<!-- {tag}: end -->"))
}

/// The document's text and the byte offsets of region `name`'s begin and end markers.
fn find_region(doc: &Path, name: &str) -> Result<(String, usize, usize), CliError> {
    let (begin, end) = markers(name);
    let text = std::fs::read_to_string(doc).map_err(|e| CliError::Usage(format!("{}: {e}", doc.display())))?;
    let (Some(b), Some(e)) = (text.find(&begin), text.find(&end)) else {
        return Err(CliError::Usage(format!("{}: no '{begin}' ... '{end}' region", doc.display())));
    };
    if e < b {
        return Err(CliError::Usage(format!("{}: the markers of '{name}' are out of order", doc.display())));
    }
    Ok((text, b, e))
}

/// Checks, before a long computation, that `doc` can be read and has region `name` (usage error otherwise).
pub fn check_region(doc: &Path, name: &str) -> Result<(), CliError> {
    find_region(doc, name).map(|_| ())
}

/// Replaces the text between the markers of region `name` in `doc` with `content` (atomically).
pub fn update_region(doc: &Path, name: &str, content: &str) -> Result<(), CliError> {
    let (begin, _) = markers(name);
    let (text, b, e) = find_region(doc, name)?;
    let new = format!("{}{begin}\n{content}{}", &text[..b], &text[e..]);
    crate::film::write_atomically(doc, |w| std::io::Write::write_all(w, new.as_bytes()))?;
    Ok(())
}

/// The CPU's model name (from /proc/cpuinfo) or the architecture.
pub fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string())
}

/// "`<cpu model> (<n> threads)`".
pub fn machine() -> String {
    format!("{} ({} threads)", cpu_model(), std::thread::available_parallelism().map_or(1, |n| n.get()))
}

/// Today's date (UTC) as YYYY-MM-DD.
pub fn today() -> String {
    let days =
        std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs() / 86_400) as i64;
    let (y, m, d) = crate::daylight::instant::civil_from_days(days);
    format!("{y:04}-{m:02}-{d:02}")
}

/// The Markdown tables of a command's output as JSON, for scripts: `{"tables": [{"caption", "columns", "rows"}]}`,
/// each row an object by column title, cells that are numbers as numbers. The caption is the paragraph before
/// the table (the machine and settings it was measured with). The figures are the ones of the Markdown table.
pub fn tables_json(markdown: &str) -> serde_json::Value {
    let cells = |line: &str| -> Vec<String> {
        line.trim().trim_start_matches('|').trim_end_matches('|').split('|').map(|c| c.trim().to_string()).collect()
    };
    let value = |c: &str| match c.parse::<f64>() {
        Ok(v) if v.is_finite() => serde_json::json!(v),
        _ => serde_json::json!(c),
    };
    let mut tables = Vec::new();
    let mut caption = String::new();
    let lines: Vec<&str> = markdown.lines().collect();
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i].trim();
        let is_table = line.starts_with('|') && lines.get(i + 1).is_some_and(|l| l.trim().starts_with("|--"));
        if !is_table {
            if !line.is_empty() {
                caption = line.to_string();
            }
            i += 1;
            continue;
        }
        let columns = cells(line);
        let mut rows = Vec::new();
        i += 2;
        while i < lines.len() && lines[i].trim().starts_with('|') {
            let row: serde_json::Map<String, serde_json::Value> =
                columns.iter().cloned().zip(cells(lines[i]).iter().map(|c| value(c))).collect();
            rows.push(serde_json::Value::Object(row));
            i += 1;
        }
        tables.push(serde_json::json!({ "caption": caption, "columns": columns, "rows": rows }));
        caption.clear();
    }
    serde_json::json!({ "tables": tables })
}

/// A bench's table: printed (Markdown, or its tables as JSON) and written into region `region` of each document
/// `--update` names.
pub fn publish(markdown: &str, json: bool, docs: &[std::path::PathBuf], region: &str) -> Result<(), CliError> {
    print_output(markdown, json);
    for doc in docs {
        update_region(doc, region, markdown)?;
        eprintln!("sunshade bench: updated {}", doc.display());
    }
    Ok(())
}

/// Prints a command's Markdown output, or its tables as JSON.
pub fn print_output(markdown: &str, json: bool) {
    if json {
        println!("{}", serde_json::to_string_pretty(&tables_json(markdown)).expect("serialisable"));
    } else {
        print!("{markdown}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markdown_tables_become_json_rows() {
        let md = "Measured on a machine.\n\n| scene | max rel | GPU frame [ms] |\n|---|---:|---:|\n| a.glb | 8.0e-6 | 23.15 |\n| b | — | 1 |\n";
        let j = tables_json(md);
        assert_eq!(j["tables"][0]["caption"], "Measured on a machine.");
        assert_eq!(j["tables"][0]["rows"][0]["max rel"], 8.0e-6);
        assert_eq!(j["tables"][0]["rows"][0]["GPU frame [ms]"], 23.15);
        assert_eq!(j["tables"][0]["rows"][1]["max rel"], "—");
        assert_eq!(j["tables"].as_array().unwrap().len(), 1);
    }
}

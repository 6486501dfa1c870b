//! Documentation tables from vector files: one table per command with request,
//! response and meaning. Errata are shown as errata.

use super::{Expected, Vector, VectorFile};
use serde::Serialize;
use std::collections::BTreeMap;

#[derive(Debug, Serialize)]
pub struct Row {
    pub id: String,
    pub request: String,
    pub response: String,
    pub result: Expected,
    pub meaning: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub erratum: Option<String>,
}

#[derive(Debug, Serialize)]
pub struct Table {
    pub command: String,
    pub rows: Vec<Row>,
}

/// One table per command, commands in byte order; steps of a sequence are rows.
pub fn tables(files: &[VectorFile]) -> Vec<Table> {
    let mut by_command: BTreeMap<String, Vec<Row>> = BTreeMap::new();
    for v in files.iter().flat_map(|f| &f.vectors) {
        by_command.entry(v.command.clone()).or_default().extend(rows(v));
    }
    by_command.into_iter().map(|(command, rows)| Table { command, rows }).collect()
}

fn rows(v: &Vector) -> Vec<Row> {
    let erratum =
        v.erratum.as_ref().map(|e| format!("printed `{}`, corrected `{}`: {}", e.printed, e.corrected, e.reason));
    if let Some(t) = &v.table_case {
        return vec![Row {
            id: v.id.clone(),
            request: t.input.clone(),
            response: t.output.clone(),
            result: v.result,
            meaning: v.meaning.clone(),
            erratum,
        }];
    }
    if let Some(c) = &v.checksum_example {
        return vec![Row {
            id: v.id.clone(),
            request: c.frame.clone(),
            response: format!("checksum {}", c.checksum),
            result: v.result,
            meaning: v.meaning.clone(),
            erratum,
        }];
    }
    let many = v.steps.len() > 1;
    v.steps
        .iter()
        .enumerate()
        .map(|(i, s)| Row {
            id: if many { format!("{} #{}", v.id, i + 1) } else { v.id.clone() },
            request: s.request.clone(),
            response: s.response.clone().unwrap_or_else(|| "(no response)".into()),
            result: if i + 1 == v.steps.len() { v.result } else { Expected::Valid },
            meaning: s.note.clone().unwrap_or_else(|| v.meaning.clone()),
            erratum: erratum.clone(),
        })
        .collect()
}

pub fn markdown(files: &[VectorFile]) -> String {
    let mut s = String::from("# HIPERFACE vectors\n\nGenerated from the vector files by `hiperface vectors export`.\n");
    for t in tables(files) {
        s.push_str(&format!(
            "\n## {}\n\n| id | request | response | result | meaning |\n|---|---|---|---|---|\n",
            t.command
        ));
        for r in t.rows {
            let result = match r.result {
                Expected::Valid => "valid",
                Expected::Acceptable => "acceptable",
                Expected::Invalid => "**invalid**",
            };
            let meaning = match &r.erratum {
                Some(e) => format!("{} (**erratum**: {e})", r.meaning),
                None => r.meaning.clone(),
            };
            s.push_str(&format!(
                "| `{}` | `{}` | `{}` | {result} | {} |\n",
                r.id,
                r.request,
                r.response,
                meaning.replace('|', "\\|")
            ));
        }
    }
    s
}

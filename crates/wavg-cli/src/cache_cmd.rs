//! `wavg cache list|clear`: what the embedding cache holds, and emptying it.

use crate::CliError;
use crate::cache;

/// `wavg cache` subcommands.
#[derive(clap::Subcommand)]
pub enum Command {
    /// List the cached embeddings: key, size, mesh, vertices, landmarks, age.
    #[command(after_long_help = "\
One line per cached embedding: key, size, vertices, landmarks, the seconds it took, age,
and the mesh as first named. --json prints dir and entries (each key, bytes, mesh,
vertices, faces, landmarks, seconds, created; all but key and bytes null for an entry
whose description is missing or damaged).")]
    List(ListArgs),
    /// Remove every cached embedding.
    #[command(after_long_help = "\
Removes every cached embedding (the files the cache named: KEY.wavg and KEY.json) and says
how much space it freed; other .wavg files in the folder are kept, and counted.")]
    Clear,
}

/// Arguments of `wavg cache list`.
#[derive(clap::Args)]
pub struct ListArgs {
    /// Print one JSON object: dir, entries (key, bytes, mesh, vertices, faces, landmarks,
    /// seconds, created, writer: the door that computed it, `cli`, `python`, `blender`,
    /// `serve`, `batch` or `c`).
    #[arg(long)]
    pub json: bool,
}

/// Runs `wavg cache list` or `wavg cache clear`.
pub fn run(cmd: Command) -> Result<(), CliError> {
    let cache = cache::open(false).ok_or_else(|| {
        CliError::input("no cache folder: set WAVG_CACHE_DIR, XDG_CACHE_HOME or HOME")
    })?;
    let dir = cache.dir();
    let entries = cache.entries()?;
    match cmd {
        Command::List(a) if a.json => {
            let list: Vec<serde_json::Value> = entries
                .iter()
                .map(|e| {
                    // An entry whose description is missing or damaged has the same keys,
                    // null.
                    let mut v = e
                        .meta
                        .as_ref()
                        .and_then(|m| serde_json::to_value(m).ok())
                        .unwrap_or_else(|| {
                            serde_json::json!({
                                "mesh": null, "vertices": null, "faces": null,
                                "landmarks": null, "seconds": null, "created": null,
                                "writer": null,
                            })
                        });
                    v["key"] = e.key.clone().into();
                    v["bytes"] = e.bytes.into();
                    v
                })
                .collect();
            let j = serde_json::json!({ "dir": dir.display().to_string(), "entries": list });
            println!("{j}");
        }
        Command::List(_) => {
            println!("{} ({} entries)", dir.display(), entries.len());
            let now = std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_secs());
            for e in &entries {
                let (key, size) = (&e.key, format!("{:.1} MB", e.bytes as f64 / 1e6));
                match &e.meta {
                    Some(m) => println!(
                        "{key}  {size:>9}  {} vertices, {} landmarks, {:.1} s to compute, \
                         {} h old, by {}  {}",
                        m.vertices,
                        m.landmarks,
                        m.seconds,
                        now.saturating_sub(m.created) / 3600,
                        if m.writer.is_empty() { "?" } else { &m.writer },
                        m.mesh
                    ),
                    None => println!("{key}  {size:>9}"),
                }
            }
        }
        Command::Clear => {
            let (removed, freed) = cache.clear()?;
            println!(
                "removed {removed} cached embeddings ({:.1} MB) from {}",
                freed as f64 / 1e6,
                dir.display()
            );
            let kept = cache.others()?.len();
            if kept > 0 {
                println!("kept {kept} other .wavg files there (not named by the cache)");
            }
        }
    }
    Ok(())
}

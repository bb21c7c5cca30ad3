//! `scenefit free SCENE [--free GLOB... -o OUT.json]`: lists the fields a
//! scene offers as free parameters with their values and default bounds,
//! or writes the scene with the fields a spec matches made free
//! (docs/interchange.md, "Free parameters").

use crate::error::{Error, Result};
use crate::interchange::free_spec;
use crate::scene::{Bound, Value};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct FreeArgs {
    /// The scene file (JSON).
    scene: PathBuf,
    /// Make the fields this glob matches free (`*` within one segment:
    /// `lights.*.position`); repeatable. Needs -o.
    #[arg(long = "free", value_name = "GLOB", requires = "output")]
    free: Vec<String>,
    /// Where to write the scene with its new free entries.
    #[arg(short, long, requires = "free")]
    output: Option<PathBuf>,
}

pub fn run(a: FreeArgs) -> Result<()> {
    let mut scene = crate::scene::load(&a.scene)?;
    let file = a.scene.display().to_string();
    let Some(out) = &a.output else {
        print_offers(&scene);
        return Ok(());
    };
    if std::fs::canonicalize(out).ok() == std::fs::canonicalize(&a.scene).ok() && out.exists() {
        return Err(Error::Usage(format!(
            "-o {}: is the scene read; expected a new file name",
            out.display()
        )));
    }
    let added = free_spec::apply(&mut scene, &a.free, &file)?;
    let value = serde_json::to_value(&scene)
        .map_err(|e| Error::Run(format!("cannot serialise the scene: {e}")))?;
    crate::scene::load::from_value(value.clone(), &out.display().to_string())?;
    let text = serde_json::to_string_pretty(&value)
        .map_err(|e| Error::Run(format!("cannot serialise the scene: {e}")))?;
    crate::fsio::write_atomic(out, format!("{text}\n").as_bytes())?;
    for p in &added {
        println!("free: {p}");
    }
    println!("{} entries added; {} written", added.len(), out.display());
    Ok(())
}

fn print_offers(scene: &crate::scene::Scene) {
    let show = |v: Vec<f64>| {
        let s: Vec<String> = v
            .iter()
            .map(|x| format!("{}", (x * 1e6).round() / 1e6))
            .collect();
        if s.len() == 1 {
            s[0].clone()
        } else {
            format!("[{}]", s.join(", "))
        }
    };
    let bound = |b: Bound, n: usize| show(b.components(n));
    println!(
        "{:<40} {:<34} {:<34} {:<34} free",
        "path", "value", "default min", "default max"
    );
    for o in free_spec::offers(scene) {
        let n = o.value.components().len();
        let is_free = scene.free.iter().any(|f| f.param == o.path);
        let value = match o.value {
            Value::Scalar(x) => show(vec![x]),
            Value::Vector(v) => show(v.to_vec()),
        };
        println!(
            "{:<40} {:<34} {:<34} {:<34} {}",
            o.path,
            value,
            bound(o.min, n),
            bound(o.max, n),
            if is_free { "yes" } else { "" }
        );
    }
}

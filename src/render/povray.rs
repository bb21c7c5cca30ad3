//! The POV-Ray 3.7 backend: each render is one `povray` process (one thread,
//! `+WT1`) reading a scene written by `pov_sdl.rs`; many run at once, since a
//! render is mostly start-up wait (~0.7 s of wall time, ~0.02 s of CPU).
//!
//! Scene fields: everything `pov_sdl.rs` lists, plus `image` (`+W +H`) and
//! `render.antialias` n: n > 1 supersamples every pixel on an n x n grid
//! (`+A0.0 +AM1 +Rn -J`; POV-Ray adds the pixel centre, so the centre
//! weighs 2/(n^2+1) instead of 1/n^2), n = 1 one ray through the pixel
//! centre (`-A`), as the built-in tracer does. `render.samples` and the
//! sampler seed are unused: POV-Ray is deterministic.

use super::backend::Backend;
use super::external::{session_dir, ExternalSession, Files, OneShotBackend, Process};
use super::{pov_sdl, RenderSession};
use crate::error::{Error, Result};
use crate::exec::discover;
use crate::exec::process::CommandSpec;
use crate::scene::Scene;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The registry's entry (`registry::ALL`).
pub const BACKEND: Backend = Backend {
    name: "povray",
    arg: None,
    about: "POV-Ray 3.7, one process per render",
    build: |_, opts| Box::new(PovRay(opts)),
    supports: pov_sdl::refusals,
};

/// Default per-render timeout: a render takes about a second, several
/// when 64 share two cores.
const RENDER_TIMEOUT: Duration = Duration::from_secs(120);

/// Processes at once by default: a render is ~0.65 s of POV-Ray sleeping and
/// ~30 ms of CPU, so a whole generation of the paper's 80 should run at once;
/// 128 beat 64 on 2 cores (docs/benchmarks-backends.md). ~15 MB each.
pub const DEFAULT_JOBS: usize = 128;

/// The POV-Ray backend, with the caller's process options.
pub struct PovRay(pub super::RenderOptions);

impl Process for PovRay {
    fn name(&self) -> String {
        "povray".into()
    }

    fn default_jobs(&self) -> Option<usize> {
        Some(DEFAULT_JOBS)
    }

    fn start(&self, jobs: usize) -> Result<Box<dyn RenderSession>> {
        let program = discover::find("povray", &discover::apt_hint("povray"))?;
        let (cfg, dir) = session_dir(jobs, (RENDER_TIMEOUT, RENDER_TIMEOUT), &self.0)?;
        let version = version(&program);
        let maps = super::pov_maps::PovMaps::new(dir.path());
        let backend = PovBackend { program, maps };
        confine(dir.path())?;
        Ok(Box::new(ExternalSession::one_shot(
            Box::new(backend),
            cfg,
            version,
            dir,
        )?))
    }
}

struct PovBackend {
    program: PathBuf,
    /// the texture maps written into the run directory (`pov_maps`)
    maps: super::pov_maps::PovMaps,
}

impl OneShotBackend for PovBackend {
    fn extension(&self) -> &'static str {
        "pov"
    }

    fn scene_text(&self, scene: &Scene) -> std::result::Result<String, String> {
        let text = pov_sdl::sdl_with(scene, &|t, k, f| self.maps.get(t, k, f))?;
        only_version_directive(&text)?;
        Ok(text)
    }

    fn command(&self, files: &Files, scene: &Scene, _seed: u64) -> CommandSpec {
        CommandSpec::new(&self.program)
            .cwd(files.dir)
            .env("HOME", files.dir) // reads the povray.conf of `confine`, not the user's
            .args(arguments(scene, &files.scene, &files.image))
    }
}

/// POV-Ray's user configuration for a run directory `dir`, used as the
/// povray processes' HOME: file I/O restricted to the working directory
/// (the run directory), no shell-outs, and none of the user's own
/// povray.ini or include paths. POV-Ray 3.7.0's parser of the
/// `[File I/O Security]` line is broken (the setting is always read as
/// unset, so the system file's restrictions are off too); the paths still
/// replace the system's, and fixed versions enforce them. The SDL itself
/// never holds scene text (`pov_sdl`), and `only_version_directive`
/// refuses any other directive, so this is the second line of defence.
fn confine(dir: &Path) -> Result<()> {
    let conf_dir = dir.join(".povray").join("3.7");
    std::fs::create_dir_all(&conf_dir).map_err(|e| Error::io(&conf_dir, e))?;
    let conf = conf_dir.join("povray.conf");
    let text = "[File I/O Security]\nrestricted\n[Shellout Security]\nforbidden\n[Permitted Paths]\nread+write = .\n";
    std::fs::write(&conf, text).map_err(|e| Error::io(&conf, e))
}

/// Refuses SDL with a directive other than `#version`: the written scene
/// has none (no `#fopen`, `#include`, `#write`), whatever the scene holds.
pub fn only_version_directive(sdl: &str) -> std::result::Result<(), String> {
    let stray = sdl
        .char_indices()
        .filter(|&(_, c)| c == '#')
        .any(|(i, _)| !sdl[i..].starts_with("#version 3.7;"));
    if stray {
        return Err("internal error: the POV-Ray scene holds a directive other than #version; refusing to run it".into());
    }
    Ok(())
}

/// The command line of one render (relative paths: POV-Ray may write only
/// in its working directory and /tmp by default).
pub fn arguments(scene: &Scene, input: &str, output: &str) -> Vec<String> {
    let mut a = vec![
        format!("+I{input}"),
        format!("+O{output}"),
        format!("+W{}", scene.image.width),
        format!("+H{}", scene.image.height),
        "+FN".into(), // PNG, 8 bits, sRGB-encoded (file_gamma defaults to sRGB)
        "-D".into(),  // no display
        "-P".into(),  // no pause
        "+Q9".into(),
        "+WT1".into(), // one thread: many processes run at once instead
        "-GS".into(),  // no statistics, render progress or debug text
        "-GR".into(),
        "-GD".into(),
        "-RVP".into(), // no radiosity preview
    ];
    let n = scene.render.antialias.max(1);
    if n > 1 {
        a.extend(["+A0.0".into(), "+AM1".into(), format!("+R{n}"), "-J".into()]);
    } else {
        a.push("-A".into());
    }
    a
}

/// "povray 3.7.0.10" from `povray --version`, or "povray".
fn version(program: &Path) -> String {
    let out = std::process::Command::new(program)
        .arg("--version")
        .stdin(std::process::Stdio::null())
        .output();
    let text = out
        .map(|o| {
            format!(
                "{}{}",
                String::from_utf8_lossy(&o.stdout),
                String::from_utf8_lossy(&o.stderr)
            )
        })
        .unwrap_or_default();
    text.lines()
        .find_map(|l| {
            l.trim()
                .strip_prefix("POV-Ray ")
                .map(|v| format!("povray {}", v.trim()))
        })
        .unwrap_or_else(|| "povray".into())
}

//! Any program as a renderer (docs/plugins.md):
//! - `cmd:TEMPLATE`, one process per render: TEMPLATE is split into words
//!   like a shell would (quotes, backslashes; no shell runs), and `{scene}`,
//!   `{output}` and `{seed}` are replaced in every word by the scene file
//!   (JSON, the scene without its `free` list), the PNG to write and the
//!   sampler seed. Without `{scene}` and `{output}` both are appended.
//!   Exit 0 and an image of the scene's size, or the render failed.
//! - `worker:COMMAND`, persistent: COMMAND is started `jobs` times and
//!   spoken to in JSON lines (the protocol of docs/plugins.md).
//!
//! Both run in the user's working directory, so relative paths in the
//! command work as typed. Every scene field is passed through unchanged.

use super::backend::Backend;
use super::external::{session_dir, started, ExternalSession, Files, OneShotBackend, Process};
use super::{RenderOptions, RenderSession};
use crate::error::{Error, Result};
use crate::exec::discover;
use crate::exec::process::CommandSpec;
use crate::scene::Scene;
use std::path::PathBuf;
use std::time::Duration;

/// The registry's entry for `cmd:TEMPLATE`: every field is passed on.
pub const ONE_SHOT: Backend = Backend {
    name: "cmd:",
    arg: Some("TEMPLATE"),
    about: "any program, one process per render (docs/plugins.md)",
    build: |template, opts| Box::new(Command::one_shot(template, opts)),
    supports: |_| Vec::new(),
};

/// The registry's entry for `worker:COMMAND`: every field is passed on.
pub const WORKER: Backend = Backend {
    name: "worker:",
    arg: Some("COMMAND"),
    about: "any program as a persistent worker speaking JSON lines (docs/plugins.md)",
    build: |command, opts| Box::new(Command::worker(command, opts)),
    supports: |_| Vec::new(),
};

/// Default per-render timeout of plug-ins (a plug-in's speed is unknown).
const RENDER_TIMEOUT: Duration = Duration::from_secs(300);
const STARTUP_TIMEOUT: Duration = Duration::from_secs(120);

const HINT: &str = "give the program's path or put it on PATH";

/// A plug-in renderer: `cmd:TEMPLATE` or `worker:COMMAND`.
pub struct Command {
    kind: Kind,
    /// The template or command, after its prefix.
    text: String,
    opts: RenderOptions,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    OneShot,
    Worker,
}

impl Command {
    /// `cmd:TEMPLATE`.
    pub fn one_shot(template: &str, opts: RenderOptions) -> Command {
        Command {
            kind: Kind::OneShot,
            text: template.to_string(),
            opts,
        }
    }

    /// `worker:COMMAND`.
    pub fn worker(command: &str, opts: RenderOptions) -> Command {
        Command {
            kind: Kind::Worker,
            text: command.to_string(),
            opts,
        }
    }

    fn prefix(&self) -> &'static str {
        match self.kind {
            Kind::OneShot => "cmd:",
            Kind::Worker => "worker:",
        }
    }
}

/// The words of a command, the program resolved to a full path.
fn words(spec: &str, what: &str) -> Result<(PathBuf, Vec<String>)> {
    let words = shell_words::split(spec).map_err(|e| {
        Error::Usage(format!(
            "--renderer {what}{spec}: cannot split the command into words: {e}"
        ))
    })?;
    let Some((program, rest)) = words.split_first() else {
        return Err(Error::Usage(format!(
            "--renderer {what}: expected a command after \"{what}\""
        )));
    };
    if program.contains('{') {
        return Err(Error::Usage(format!(
            "--renderer {what}{spec}: the first word must be the program, got \"{program}\""
        )));
    }
    let path = discover::find(program, HINT)?;
    // the path must survive a change of working directory
    let path = std::fs::canonicalize(&path).unwrap_or(path);
    Ok((path, rest.to_vec()))
}

impl Process for Command {
    fn name(&self) -> String {
        format!("{}{}", self.prefix(), self.text)
    }

    fn start(&self, jobs: usize) -> Result<Box<dyn RenderSession>> {
        let (program, mut args) = words(&self.text, self.prefix())?;
        if self.kind == Kind::OneShot {
            args = template_args(&self.text, args)?;
        }
        let (cfg, dir) = session_dir(jobs, (RENDER_TIMEOUT, STARTUP_TIMEOUT), &self.opts)?;
        match self.kind {
            Kind::OneShot => {
                let backend = Template { program, args };
                Ok(Box::new(ExternalSession::one_shot(
                    Box::new(backend),
                    cfg,
                    self.name(),
                    dir,
                )?))
            }
            Kind::Worker => {
                let spec = CommandSpec::new(program).args(args);
                started(ExternalSession::persistent(&self.name(), spec, cfg, dir))
            }
        }
    }
}

/// A `cmd:` template's words with `{scene}` and `{output}` in place:
/// both given, or both appended.
fn template_args(template: &str, mut args: Vec<String>) -> Result<Vec<String>> {
    let has = |p: &str| args.iter().any(|a| a.contains(p));
    match (has("{scene}"), has("{output}")) {
        (true, true) => {}
        (false, false) => args.extend(["{scene}".to_string(), "{output}".to_string()]),
        _ => {
            return Err(Error::Usage(format!(
                "--renderer cmd:{template}: the template needs both {{scene}} and {{output}} (or neither: then they are appended)"
            )))
        }
    }
    Ok(args)
}

struct Template {
    program: PathBuf,
    args: Vec<String>,
}

impl OneShotBackend for Template {
    fn extension(&self) -> &'static str {
        "json"
    }

    fn scene_text(&self, scene: &Scene) -> std::result::Result<String, String> {
        serde_json::to_string_pretty(&super::external::plain_scene(scene))
            .map_err(|e| format!("cannot write the scene: {e}"))
    }

    fn command(&self, files: &Files, _scene: &Scene, seed: u64) -> CommandSpec {
        let scene_path = files.dir.join(&files.scene);
        let output = files.dir.join(&files.image);
        let (sp, op, sd) = (
            scene_path.to_string_lossy(),
            output.to_string_lossy(),
            seed.to_string(),
        );
        let args = self.args.iter().map(|a| {
            a.replace("{scene}", &sp)
                .replace("{output}", &op)
                .replace("{seed}", &sd)
        });
        CommandSpec::new(&self.program).args(args)
    }
}

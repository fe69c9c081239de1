//! The one argument style for a command's mesh: positional (`wavg info spot.obj`) or as
//! `--mesh spot.obj`, the two being the same argument.

use clap::{ArgGroup, Args, FromArgMatches};

/// The mesh a command works on, given positionally or with `--mesh` (exactly one of them).
/// Flatten it into a command's arguments; it dereferences to the path or `builtin:NAME`.
#[derive(Clone, Debug)]
pub struct MeshArg(String);

/// Help text of both spellings.
const HELP: &str = "Mesh file (.obj/.off/.ply, optionally .gz; .gltf/.glb, FILE#NAME for one \
                    mesh) or builtin:NAME; positional or as --mesh";
/// Argument ids (the positional's and the flag's) and their group.
const POSITIONAL: &str = "mesh_positional";
const FLAG: &str = "mesh";
const GROUP: &str = "mesh_source";

impl MeshArg {
    /// The two spellings on `cmd`, `required` or not (a command with a default mesh).
    fn add(cmd: clap::Command, required: bool) -> clap::Command {
        cmd.arg(
            clap::Arg::new(POSITIONAL)
                .value_name("MESH")
                .help(HELP)
                .conflicts_with(FLAG),
        )
        .arg(
            clap::Arg::new(FLAG)
                .long("mesh")
                .value_name("MESH")
                .help(HELP),
        )
        .group(
            ArgGroup::new(GROUP)
                .args([POSITIONAL, FLAG])
                .required(required),
        )
    }

    fn from_matches(m: &clap::ArgMatches) -> Option<String> {
        m.get_one::<String>(POSITIONAL)
            .or_else(|| m.get_one::<String>(FLAG))
            .cloned()
    }
}

impl std::ops::Deref for MeshArg {
    type Target = str;
    fn deref(&self) -> &str {
        &self.0
    }
}

impl std::fmt::Display for MeshArg {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl AsRef<std::path::Path> for MeshArg {
    fn as_ref(&self) -> &std::path::Path {
        std::path::Path::new(&self.0)
    }
}

impl FromArgMatches for MeshArg {
    fn from_arg_matches(m: &clap::ArgMatches) -> Result<Self, clap::Error> {
        Self::from_matches(m)
            .map(Self)
            .ok_or_else(|| clap::Error::new(clap::error::ErrorKind::MissingRequiredArgument))
    }

    fn update_from_arg_matches(&mut self, m: &clap::ArgMatches) -> Result<(), clap::Error> {
        if let Some(s) = Self::from_matches(m) {
            self.0 = s;
        }
        Ok(())
    }
}

impl Args for MeshArg {
    fn augment_args(cmd: clap::Command) -> clap::Command {
        Self::add(cmd, true)
    }

    fn augment_args_for_update(cmd: clap::Command) -> clap::Command {
        Self::add(cmd, true)
    }
}

/// Like [`MeshArg`] but optional: `None` when neither spelling is given (the command has
/// a default mesh).
#[derive(Clone, Debug)]
pub struct OptionalMeshArg(pub Option<String>);

impl FromArgMatches for OptionalMeshArg {
    fn from_arg_matches(m: &clap::ArgMatches) -> Result<Self, clap::Error> {
        Ok(Self(MeshArg::from_matches(m)))
    }

    fn update_from_arg_matches(&mut self, m: &clap::ArgMatches) -> Result<(), clap::Error> {
        if let Some(s) = MeshArg::from_matches(m) {
            self.0 = Some(s);
        }
        Ok(())
    }
}

impl Args for OptionalMeshArg {
    fn augment_args(cmd: clap::Command) -> clap::Command {
        MeshArg::add(cmd, false)
    }

    fn augment_args_for_update(cmd: clap::Command) -> clap::Command {
        MeshArg::add(cmd, false)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        mesh: MeshArg,
        #[arg(long)]
        json: bool,
    }

    #[test]
    fn positional_and_flag_are_the_same_argument() {
        let a = Cli::try_parse_from(["x", "a.obj", "--json"]).unwrap();
        assert_eq!(&*a.mesh, "a.obj");
        assert!(a.json);
        let b = Cli::try_parse_from(["x", "--mesh", "b.obj"]).unwrap();
        assert_eq!(&*b.mesh, "b.obj");
        assert!(Cli::try_parse_from(["x", "a.obj", "--mesh", "b.obj"]).is_err());
        assert!(Cli::try_parse_from(["x", "--json"]).is_err());
    }
}

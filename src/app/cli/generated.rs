//! `tapsim completions` and `tapsim man`: shell completions and man pages generated from
//! the command line's own definitions, so that they never drift from its flags.

use crate::error::{Error, Result};
use clap::{Args, CommandFactory};
use std::path::PathBuf;

/// Print the completion script of SHELL for every command and flag.
///
///   tapsim completions bash > ~/.local/share/bash-completion/completions/tapsim
///   tapsim completions zsh > ~/.zfunc/_tapsim         # with fpath+=~/.zfunc
///   tapsim completions fish > ~/.config/fish/completions/tapsim.fish
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct CompletionsArgs {
    /// The shell.
    shell: clap_complete::Shell,
}

/// Write a man page for tapsim and for each command into a directory (tapsim.1,
/// tapsim-tap.1, …), from the same text as --help.
///
///   tapsim man --out ~/.local/share/man/man1 && man tapsim-tap
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct ManArgs {
    /// The directory to write the pages into (it must exist).
    #[arg(long)]
    out: PathBuf,
    /// No notes of files written on stderr.
    #[arg(long, short = 'q')]
    pub(super) quiet: bool,
}

/// Print the completions.
pub fn completions(args: CompletionsArgs) -> Result<()> {
    let mut command = super::Cli::command();
    let mut script = Vec::new();
    clap_complete::generate(args.shell, &mut command, "tapsim", &mut script);
    out!("{}", String::from_utf8_lossy(&script));
    Ok(())
}

/// Write the man pages.
pub fn man(args: ManArgs) -> Result<()> {
    if !args.out.is_dir() {
        return Err(Error::NotApplicable(format!(
            "--out {}: give an existing directory",
            args.out.display()
        )));
    }
    let root = super::Cli::command();
    let mut pages = vec![("tapsim".to_string(), root.clone())];
    for sub in root.get_subcommands() {
        let name = format!("tapsim-{}", sub.get_name());
        let page = sub
            .clone()
            .display_name(name.clone())
            .bin_name(format!("tapsim {}", sub.get_name()));
        pages.push((name, page));
    }
    for (name, command) in pages {
        let mut page = Vec::new();
        clap_mangen::Man::new(command)
            .title(name.to_uppercase())
            .render(&mut page)
            .map_err(|e| Error::Numerical(format!("the man page of {name}: {e}")))?;
        crate::app::report::output::write_bytes(&args.out.join(format!("{name}.1")), &page)?;
    }
    Ok(())
}

//! `tapsim completions` and `tapsim man`: shell completions and man pages generated from
//! the command line's own definitions, so that they never drift from its flags.

use crate::error::{Error, Result};
use clap::Args;
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
/// tapsim-tap.1, …), from the same text as --help; or, with --markdown, every command's
/// --help as one Markdown page (the guide's command reference).
///
///   tapsim man --out ~/.local/share/man/man1 && man tapsim-tap
///   tapsim man --markdown docs/src/reference/commands.md
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct ManArgs {
    /// The directory to write the pages into (it must exist).
    #[arg(
        long,
        required_unless_present = "markdown",
        conflicts_with = "markdown"
    )]
    out: Option<PathBuf>,
    /// Write every command's --help, at 80 columns, as one Markdown page.
    #[arg(long, value_name = "FILE.md")]
    markdown: Option<PathBuf>,
    /// No notes of files written on stderr.
    #[arg(long, short = 'q')]
    pub(super) quiet: bool,
}

/// Print the completions.
pub fn completions(args: CompletionsArgs) -> Result<()> {
    let mut command = super::command();
    let mut script = Vec::new();
    clap_complete::generate(args.shell, &mut command, "tapsim", &mut script);
    out!("{}", String::from_utf8_lossy(&script));
    Ok(())
}

/// Every command's --help at 80 columns, as Markdown: the guide's command reference.
pub fn reference() -> String {
    let mut root = super::command().term_width(80);
    let mut text = String::from(
        "# Command reference\n\nEvery command's `--help`, generated from the command line's own \
         definitions (`tapsim man --markdown docs/src/reference/commands.md`; a test checks \
         this page is current). `-h` shows a one-screen summary of the same.\n",
    );
    text.push_str(&format!(
        "\n## tapsim\n\n```text\n{}\n```\n",
        root.render_long_help().to_string().trim_end()
    ));
    for sub in root.get_subcommands_mut() {
        let name = sub.get_name().to_string();
        let mut sub = sub
            .clone()
            .term_width(80)
            .bin_name(format!("tapsim {name}"));
        text.push_str(&format!(
            "\n## tapsim {name}\n\n```text\n{}\n```\n",
            sub.render_long_help().to_string().trim_end()
        ));
    }
    text
}

/// Write the man pages, or the Markdown reference.
pub fn man(args: ManArgs) -> Result<()> {
    if let Some(path) = &args.markdown {
        return crate::app::report::output::write_bytes(path, reference().as_bytes());
    }
    let Some(out) = args.out else {
        return Err(Error::NotApplicable(
            "give --out DIR or --markdown FILE.md".into(),
        ));
    };
    if !out.is_dir() {
        return Err(Error::NotApplicable(format!(
            "--out {}: give an existing directory",
            out.display()
        )));
    }
    let root = super::command();
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
        crate::app::report::output::write_bytes(&out.join(format!("{name}.1")), &page)?;
    }
    Ok(())
}

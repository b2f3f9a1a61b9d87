fn main() -> std::process::ExitCode {
    tapsim::app::cli::main()
}

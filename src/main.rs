fn main() -> std::process::ExitCode {
    tapsim::cli::main()
}

fn main() -> std::process::ExitCode {
    sunshade::cli::main()
}

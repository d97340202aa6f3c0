use clap::Parser;

fn main() {
    let cli = ocular::cli::Cli::parse();
    if let Err(error) = ocular::cli::run(cli) {
        eprintln!("error: {error}");
        std::process::exit(error.exit_code());
    }
}

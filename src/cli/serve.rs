//! `subgram serve`: its arguments, and the server started.

use std::time::Duration;

use subgram::Error;

#[derive(clap::Args)]
pub(super) struct ServeCli {
    /// An .lsys file, or an lpfg model folder.
    file: String,
    /// The port (0: any free one).
    #[arg(long, default_value_t = 8080)]
    port: u16,
    /// Let the page write the program back (atomically).
    #[arg(long)]
    save: bool,
    #[arg(short = 'D', value_name = "NAME=VALUE")]
    define: Vec<String>,
    /// Compute float, V2f and V3f in double precision (lpfg: single).
    #[arg(long)]
    double: bool,
    /// The largest word a render may make.
    #[arg(long, default_value_t = 2_000_000)]
    max_modules: usize,
    /// The longest a render may take, in seconds.
    #[arg(long, value_name = "SECONDS", default_value_t = 10)]
    timeout: u64,
}

impl ServeCli {
    pub(super) fn run(self) -> Result<(), Error> {
        let ServeCli {
            file,
            port,
            save,
            define,
            double,
            max_modules,
            timeout,
        } = self;
        let opts = subgram::serve::ServeOptions {
            path: file.into(),
            port,
            save,
            limits: subgram::serve::Limits {
                max_modules,
                timeout: Duration::from_secs(timeout.max(1)),
                ..Default::default()
            },
            defines: define,
            double,
        };
        let server = subgram::serve::Server::bind(opts)?;
        println!("serving {} (Ctrl-C to stop)", server.url());
        use std::io::Write;
        let _ = std::io::stdout().flush();
        server.run();
        Ok(())
    }
}

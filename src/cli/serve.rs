//! `subgram serve` and `subgram view`: their arguments, and the server
//! started (and, for `view`, its page opened in the default browser).

use std::time::Duration;

use subgram::Error;

#[derive(clap::Args)]
pub(super) struct ServeCli {
    /// An .lsys file, or an lpfg model folder.
    file: String,
    /// The port (0: any free one) [default: 8080; `view`: 8080, or any
    /// free one when 8080 is taken].
    #[arg(long)]
    port: Option<u16>,
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

/// The port `serve` listens on when none is given.
const DEFAULT_PORT: u16 = 8080;

impl ServeCli {
    /// `subgram serve`.
    pub(super) fn run(self) -> Result<(), Error> {
        self.start(false)
    }

    /// `subgram view`: `serve`, and the page opened in the default
    /// browser (`$BROWSER` first); where none opens, the address is what
    /// there is.
    pub(super) fn view(self) -> Result<(), Error> {
        self.start(true)
    }

    fn start(self, open: bool) -> Result<(), Error> {
        let ServeCli {
            file,
            port,
            save,
            define,
            double,
            max_modules,
            timeout,
        } = self;
        let mut opts = subgram::serve::ServeOptions {
            path: file.into(),
            port: port.unwrap_or(DEFAULT_PORT),
            save,
            limits: subgram::serve::Limits {
                max_modules,
                timeout: Duration::from_secs(timeout.max(1)),
                ..Default::default()
            },
            defines: define,
            double,
        };
        let server = match subgram::serve::Server::bind(opts.clone()) {
            // `view` with the default port taken: any free one will do.
            Err(Error::Usage(_)) if open && port.is_none() => {
                opts.port = 0;
                subgram::serve::Server::bind(opts)?
            }
            other => other?,
        };
        let url = server.url();
        println!("serving {url} (Ctrl-C to stop)");
        use std::io::Write;
        let _ = std::io::stdout().flush();
        if open {
            // On a thread of its own: a launcher that waits for the
            // browser does not hold the server.
            std::thread::spawn(move || match opener::open_browser(&url) {
                Ok(()) => eprintln!("opened {url} in the browser"),
                Err(e) => eprintln!("no browser opened ({e}): open {url} yourself"),
            });
        }
        server.run();
        Ok(())
    }
}

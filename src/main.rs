//! The `subgram` command line: parse arguments, call the library, map errors
//! to exit codes (1 for a problem with the input, 2 for a usage error).

use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};

use subgram::{output, Derivation, DeriveOptions};

#[derive(Parser)]
#[command(
    name = "subgram",
    version,
    about = "Curves and surfaces from L-systems and grammars"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Derive an .lsys file and print the final word.
    Derive {
        file: String,
        /// Number of derivation steps (overrides `derivation length:`).
        #[arg(short = 'n', long = "steps")]
        steps: Option<u64>,
        #[arg(long, value_enum, default_value_t = Format::Text)]
        format: Format,
        /// Override a #define: -D NAME=VALUE (repeatable).
        #[arg(short = 'D', value_name = "NAME=VALUE")]
        define: Vec<String>,
        /// Stop with an error when a word grows past this many modules.
        #[arg(long, default_value_t = subgram::rewrite::derive::DEFAULT_MAX_MODULES)]
        max_modules: usize,
        /// Start the partition into multi-module strict predecessors here.
        #[arg(long, default_value_t = 0)]
        phase: usize,
        /// Print the word after interpretation rules instead.
        #[arg(long)]
        interpreted: bool,
    },
    /// Render an .lsys file's picture to PNG or SVG.
    Render {
        file: String,
        /// The picture: OUT.png or OUT.svg.
        #[arg(short = 'o', long = "output")]
        output: String,
        #[arg(short = 'n', long = "steps")]
        steps: Option<u64>,
        /// Image size in pixels, WIDTHxHEIGHT.
        #[arg(long, default_value = "800x800", value_parser = parse_size)]
        size: (u32, u32),
        /// Draw every step 0..N side by side.
        #[arg(long)]
        each: bool,
        /// white, black, none, #rrggbb.
        #[arg(long, default_value = "white", value_parser = parse_color)]
        background: subgram::render::Rgba,
        /// The projection of 3D drawings: xy, xz or yz for L-systems;
        /// iso, front, back, left, right, top or bottom for meshes.
        #[arg(long)]
        view: Option<String>,
        /// Meshes: draw the faces without their edges.
        #[arg(long)]
        no_wireframe: bool,
        #[arg(short = 'D', value_name = "NAME=VALUE")]
        define: Vec<String>,
        #[arg(long, default_value_t = subgram::rewrite::derive::DEFAULT_MAX_MODULES)]
        max_modules: usize,
        #[arg(long, default_value_t = 0)]
        phase: usize,
    },
    /// Reverse-subdivide a contour into a compact control polygon.
    Reverse {
        /// Points (`x y` or CSV), an SVG shape, or a PNG silhouette.
        input: String,
        #[arg(short = 'n', long = "steps")]
        steps: usize,
        /// The coarse polygon: .csv, .txt or .svg.
        #[arg(short = 'o', long = "output")]
        output: String,
        /// A scheme file (group 1 reverses, group 2 subdivides).
        #[arg(long)]
        scheme: Option<String>,
        /// Which pairing of points: auto (the better), 0 or 1.
        #[arg(long, default_value = "auto", value_parser = parse_phase)]
        phase: subgram::reverse::Phase,
        /// Treat the contour as open (end points kept).
        #[arg(long)]
        open: bool,
        /// Draw input, coarse polygon and reconstruction: .png or .svg.
        #[arg(long)]
        figure: Option<String>,
        /// Print point counts and reconstruction errors.
        #[arg(long)]
        report: bool,
        #[arg(long, value_enum, default_value_t = Format::Text)]
        format: Format,
        /// Store the details that restore the input exactly.
        #[arg(long)]
        details: Option<String>,
    },
    /// Restore a contour from a coarse polygon and its details.
    Reconstruct {
        coarse: String,
        #[arg(long)]
        details: String,
        #[arg(short = 'o', long = "output")]
        output: String,
        /// Restore only this many levels (default: all).
        #[arg(long)]
        level: Option<usize>,
        /// The scheme the details were made with (default: as recorded).
        #[arg(long)]
        scheme: Option<String>,
    },
    /// Subdivide a mesh with a surface grammar.
    Subdivide {
        /// The base mesh (.obj, .off, .ply); default: the grammar's `mesh:`.
        mesh: Option<String>,
        #[arg(long)]
        grammar: String,
        #[arg(short = 'n', long = "steps")]
        steps: Option<usize>,
        /// .obj, .off, .ply, .png or .svg
        #[arg(short = 'o', long = "output")]
        output: String,
        #[arg(short = 'D', value_name = "NAME=VALUE")]
        define: Vec<String>,
        /// For pictures: iso, front, back, left, right, top, bottom.
        #[arg(long)]
        view: Option<String>,
    },
    /// Meshes: information and conversion.
    Mesh {
        #[command(subcommand)]
        command: MeshCommand,
    },
    /// Check an .lsys file and report every diagnostic.
    Check {
        file: String,
        #[arg(short = 'D', value_name = "NAME=VALUE")]
        define: Vec<String>,
    },
}

fn parse_phase(s: &str) -> Result<subgram::reverse::Phase, String> {
    match s {
        "auto" => Ok(subgram::reverse::Phase::Auto),
        "0" => Ok(subgram::reverse::Phase::Fixed(0)),
        "1" => Ok(subgram::reverse::Phase::Fixed(1)),
        _ => Err(format!("`{s}` is not a phase: use auto, 0 or 1")),
    }
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("`{s}` is not WIDTHxHEIGHT, e.g. 800x600"))?;
    let w: u32 = w
        .trim()
        .parse()
        .map_err(|_| format!("`{w}` is not a width in pixels"))?;
    let h: u32 = h
        .trim()
        .parse()
        .map_err(|_| format!("`{h}` is not a height in pixels"))?;
    if w == 0 || h == 0 || w > 20_000 || h > 20_000 {
        return Err("each side must be 1 to 20000 pixels".into());
    }
    Ok((w, h))
}

fn parse_color(s: &str) -> Result<subgram::render::Rgba, String> {
    subgram::render::Rgba::parse(s)
        .ok_or_else(|| format!("`{s}` is not a colour: use white, black, none or #rrggbb"))
}

#[derive(Subcommand)]
enum MeshCommand {
    /// Counts, boundary loops, Euler characteristic, genus, valences, levels.
    Info {
        file: String,
        #[arg(long, value_enum, default_value_t = Format::Text)]
        format: Format,
    },
    /// Check a mesh and write it in another format (.obj, .off, .ply).
    Convert {
        input: String,
        output: String,
        /// Write the triangles, not the quads of basic blocks.
        #[arg(long)]
        triangles: bool,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum Format {
    Text,
    Json,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // Deep but legal programs recurse deeply in the checker and the
    // interpreter: give them a large stack rather than a crash.
    let worker = std::thread::Builder::new()
        .stack_size(256 << 20)
        .spawn(move || run(cli));
    let result = match worker.map(|h| h.join()) {
        Ok(Ok(r)) => r,
        _ => Err((
            1,
            "error: internal failure (this is a bug in subgram)".to_string(),
        )),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err((code, message)) => {
            eprintln!("{message}");
            ExitCode::from(code)
        }
    }
}

fn run(cli: Cli) -> Result<(), (u8, String)> {
    match cli.command {
        Command::Check { file, define } => {
            if is_surface_file(&file) {
                let g = subgram::surface::load_file(std::path::Path::new(&file), &define)
                    .map_err(|e| (1, e.render()))?;
                return print_out(&format!(
                    "{file}: ok (a surface grammar of {} rules)",
                    g.rules.len()
                ));
            }
            let loaded = load(&file, &define)?;
            print_out(&format!(
                "{file}: ok ({} rules, {} module kinds)",
                loaded.program.rules.len(),
                loaded.program.alphabet.kinds.len()
            ))
        }
        Command::Reverse {
            input,
            steps,
            output,
            scheme,
            phase,
            open,
            figure,
            report,
            format,
            details,
        } => reverse_command(ReverseArgs {
            input,
            steps,
            output,
            scheme,
            phase,
            open,
            figure,
            report,
            json: matches!(format, Format::Json),
            details,
        }),
        Command::Subdivide {
            mesh,
            grammar,
            steps,
            output,
            define,
            view,
        } => {
            let (m, _) = subdivide(mesh.as_deref(), &grammar, steps, &define)?;
            write_mesh_output(&m, &output, view.as_deref())
        }
        Command::Mesh { command } => match command {
            MeshCommand::Info { file, format } => {
                let m = load_mesh(&file)?;
                let info = m.info();
                let text = match format {
                    Format::Text => info.to_string().trim_end().to_string(),
                    Format::Json => serde_json::to_string_pretty(&info)
                        .map_err(|e| (1, format!("error: {e}")))?,
                };
                print_out(&text)
            }
            MeshCommand::Convert {
                input,
                output,
                triangles,
            } => {
                let m = load_mesh(&input)?;
                let soup = if triangles {
                    m.to_soup()
                } else {
                    m.to_quad_soup()
                };
                subgram::mesh::io::write(std::path::Path::new(&output), &soup)
                    .map_err(|e| (1, e.to_string()))
            }
        },
        Command::Reconstruct {
            coarse,
            details,
            output,
            level,
            scheme,
        } => reconstruct_command(&coarse, &details, &output, level, scheme.as_deref()),
        Command::Render {
            file,
            output,
            steps,
            size,
            each,
            background,
            view,
            no_wireframe,
            define,
            max_modules,
            phase,
        } => {
            if subgram::mesh::io::Format::from_path(std::path::Path::new(&file)).is_some() {
                return render_mesh(
                    &file,
                    &output,
                    size,
                    background,
                    view.as_deref(),
                    !no_wireframe,
                );
            }
            if is_surface_file(&file) {
                let (m, _) = subdivide(None, &file, steps.map(|s| s as usize), &define)?;
                return write_mesh_picture(
                    &m,
                    &output,
                    size,
                    background,
                    view.as_deref(),
                    !no_wireframe,
                );
            }
            let view = match view.as_deref().unwrap_or("xy") {
                "xy" => subgram::render::View::Xy,
                "xz" => subgram::render::View::Xz,
                "yz" => subgram::render::View::Yz,
                other => {
                    return Err((
                        2,
                        format!(
                        "error: `--view {other}` is not a view of an L-system: use xy, xz or yz"
                    ),
                    ))
                }
            };
            let lower = output.to_ascii_lowercase();
            let svg = if lower.ends_with(".svg") {
                true
            } else if lower.ends_with(".png") {
                false
            } else {
                return Err((
                    2,
                    format!("error: cannot tell the format of `{output}`: name it .png or .svg"),
                ));
            };
            let loaded = load(&file, &define)?;
            check_steps(steps)?;
            let mut derive = DeriveOptions::default()
                .with_max_modules(max_modules)
                .with_phase(phase);
            derive.steps = steps;
            let opts = subgram::FigureOptions {
                derive,
                each,
                draw: Default::default(),
                render: subgram::render::RenderOptions {
                    width: size.0,
                    height: size.1,
                    background,
                    view,
                    ..Default::default()
                },
            };
            let scene = loaded
                .figure(&opts)
                .map_err(|e| (1, loaded.render_figure_error(&e)))?;
            let bytes = if svg {
                subgram::render::svg::render(&scene).into_bytes()
            } else {
                subgram::render::png::render(&scene)
                    .map_err(|e| (1, format!("error: {}", e.message)))?
            };
            subgram::render::write_atomic(std::path::Path::new(&output), &bytes)
                .map_err(|e| (1, format!("error: cannot write `{output}`: {e}")))
        }
        Command::Derive {
            file,
            steps,
            format,
            define,
            max_modules,
            phase,
            interpreted,
        } => {
            if is_surface_file(&file) {
                let (m, n) = subdivide(None, &file, steps.map(|s| s as usize), &define)?;
                let info = m.info();
                let text = match format {
                    Format::Text => format!("after {n} step(s):\n{}", info.to_string().trim_end()),
                    Format::Json => serde_json::to_string_pretty(&info)
                        .map_err(|e| (1, format!("error: {e}")))?,
                };
                return print_out(&text);
            }
            let loaded = load(&file, &define)?;
            check_steps(steps)?;
            let mut opts = DeriveOptions::default()
                .with_max_modules(max_modules)
                .with_phase(phase);
            opts.steps = steps;
            let fail = |e: subgram::DeriveError| (1, loaded.render_derive_error(&e));
            let mut d = Derivation::new(&loaded.program, opts).map_err(fail)?;
            while d.has_next() {
                d.next_step().map_err(fail)?;
            }
            let word = if interpreted {
                d.interpret().map_err(fail)?
            } else {
                d.word.clone()
            };
            let p = &loaded.program;
            let text = match format {
                Format::Text => output::word_text(&word, &p.alphabet, &p.structs),
                Format::Json => {
                    output::word_json(&word, d.ring, d.step, &p.alphabet, &p.structs).to_string()
                }
            };
            print_out(&text)
        }
    }
}

fn load(file: &str, define: &[String]) -> Result<subgram::Loaded, (u8, String)> {
    subgram::load_file(file, define).map_err(|e| {
        let code = match e {
            subgram::LoadError::BadDefine(_) => 2,
            _ => 1,
        };
        (code, e.render())
    })
}

/// Writes a line to stdout; a closed pipe (`subgram derive f | head`) is not an error.
fn print_out(text: &str) -> Result<(), (u8, String)> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match writeln!(out, "{text}").and_then(|_| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        Err(e) => Err((1, format!("error: cannot write the output: {e}"))),
    }
}

/// `-n` beyond the engine's limit is a usage error.
fn check_steps(steps: Option<u64>) -> Result<(), (u8, String)> {
    match steps {
        Some(n) if n > subgram::rewrite::derive::MAX_STEPS => Err((
            2,
            format!(
                "error: -n {n} is beyond the limit of {} steps",
                subgram::rewrite::derive::MAX_STEPS
            ),
        )),
        _ => Ok(()),
    }
}

struct ReverseArgs {
    input: String,
    steps: usize,
    output: String,
    scheme: Option<String>,
    phase: subgram::reverse::Phase,
    open: bool,
    figure: Option<String>,
    report: bool,
    json: bool,
    details: Option<String>,
}

fn write_file(path: &str, bytes: &[u8]) -> Result<(), (u8, String)> {
    subgram::render::write_atomic(std::path::Path::new(path), bytes)
        .map_err(|e| (1, format!("error: cannot write `{path}`: {e}")))
}

fn reverse_command(a: ReverseArgs) -> Result<(), (u8, String)> {
    use subgram::reverse::{self, ReverseOptions, Scheme};
    let fig_svg = match &a.figure {
        Some(f) if f.to_ascii_lowercase().ends_with(".svg") => Some(true),
        Some(f) if f.to_ascii_lowercase().ends_with(".png") => Some(false),
        Some(f) => {
            return Err((
                2,
                format!("error: cannot tell the format of `{f}`: name it .png or .svg"),
            ))
        }
        None => None,
    };
    let mut contour =
        reverse::input::read(std::path::Path::new(&a.input)).map_err(|e| (1, e.to_string()))?;
    if a.open {
        contour.closed = false;
    }
    let scheme = match &a.scheme {
        Some(s) => Scheme::from_file(std::path::Path::new(s), contour.closed),
        None => Ok(Scheme::builtin(contour.closed)),
    }
    .map_err(|e| (1, e.to_string()))?;
    let opts = ReverseOptions {
        steps: a.steps,
        phase: a.phase,
        details: a.details.is_some(),
    };
    let r = reverse::reverse(&scheme, &contour, &opts).map_err(|e| (1, e.to_string()))?;
    let out = reverse::format_points(&r.coarse, contour.closed, std::path::Path::new(&a.output));
    write_file(&a.output, out.as_bytes())?;
    if let (Some(path), Some(d)) = (&a.details, &r.details) {
        let json = serde_json::to_string(d).map_err(|e| (1, format!("error: {e}")))?;
        write_file(path, json.as_bytes())?;
    }
    if a.report || fig_svg.is_some() {
        let rep = reverse::report(&scheme, &contour, &r).map_err(|e| (1, e.to_string()))?;
        if let (Some(svg), Some(path)) = (fig_svg, &a.figure) {
            let rec = scheme
                .forward(&r.coarse, a.steps)
                .map_err(|e| (1, e.to_string()))?;
            let events = reverse::figure_events(&contour, &r.coarse, &rec);
            let scene = subgram::render::scene(&[events], &Default::default())
                .map_err(|e| (1, format!("error: {}", e.message)))?;
            let bytes = if svg {
                subgram::render::svg::render(&scene).into_bytes()
            } else {
                subgram::render::png::render(&scene)
                    .map_err(|e| (1, format!("error: {}", e.message)))?
            };
            write_file(path, &bytes)?;
        }
        if a.report {
            let text = if a.json {
                serde_json::to_string_pretty(&rep).map_err(|e| (1, format!("error: {e}")))?
            } else {
                report_text(&rep)
            };
            print_out(&text)?;
        }
    }
    Ok(())
}

fn report_text(r: &subgram::reverse::Report) -> String {
    let mut s = format!(
        "input: {} points, {} ({})\nscheme: {}\n",
        r.input_points,
        if r.closed { "closed" } else { "open" },
        r.source,
        r.scheme
    );
    for st in &r.steps {
        s.push_str(&format!(
            "step {}: {} -> {} points, phase {}{}\n",
            st.step,
            st.fine,
            st.coarse,
            st.phase,
            if st.dropped {
                " (odd: the flattest point was dropped first)"
            } else {
                ""
            }
        ));
    }
    let e = |m: &subgram::reverse::metric::Error| {
        format!("max {:.6}  mean {:.6}  rms {:.6}", m.max, m.mean, m.rms)
    };
    s.push_str(&format!(
        "reconstruction error, {} points subdivided {} times, against the input:\n  reverse subdivision  {}\n  naive decimation     {}\n",
        r.coarse_points,
        r.steps.len(),
        e(&r.reverse),
        e(&r.decimation)
    ));
    if r.reverse.rms > 0.0 {
        s.push_str(&format!(
            "  decimation's rms error is {:.2} times reverse subdivision's",
            r.decimation.rms / r.reverse.rms
        ));
    }
    s
}

fn reconstruct_command(
    coarse: &str,
    details: &str,
    output: &str,
    level: Option<usize>,
    scheme: Option<&str>,
) -> Result<(), (u8, String)> {
    use subgram::reverse::{self, Details, Scheme};
    let text = std::fs::read_to_string(details)
        .map_err(|e| (1, format!("{details}: error: cannot read the file: {e}")))?;
    let d: Details = serde_json::from_str(&text).map_err(|e| {
        (
            1,
            format!("{details}:{}: error: not a details file: {e}", e.line()),
        )
    })?;
    let c = reverse::input::read(std::path::Path::new(coarse)).map_err(|e| (1, e.to_string()))?;
    let scheme = match scheme {
        Some(s) => Scheme::from_file(std::path::Path::new(s), d.closed),
        None if d.scheme.starts_with("builtin:") => Ok(Scheme::builtin(d.closed)),
        None => Scheme::from_file(std::path::Path::new(&d.scheme), d.closed),
    }
    .map_err(|e| (1, e.to_string()))?;
    let pts =
        reverse::reconstruct(&scheme, &c.points, &d, level).map_err(|e| (1, e.to_string()))?;
    let out = reverse::format_points(&pts, d.closed, std::path::Path::new(output));
    write_file(output, out.as_bytes())
}

/// Reads a mesh file and builds the half-edge mesh, with the file's name
/// on every message.
fn load_mesh(path: &str) -> Result<subgram::mesh::Mesh, (u8, String)> {
    let soup =
        subgram::mesh::io::read(std::path::Path::new(path)).map_err(|e| (1, e.to_string()))?;
    subgram::mesh::Mesh::from_soup(&soup).map_err(|e| (1, format!("{path}: error: {e}")))
}

fn render_mesh(
    file: &str,
    output: &str,
    size: (u32, u32),
    background: subgram::render::Rgba,
    view: Option<&str>,
    wireframe: bool,
) -> Result<(), (u8, String)> {
    let mesh = load_mesh(file)?;
    write_mesh_picture(&mesh, output, size, background, view, wireframe)
}

/// Loads a surface grammar, its base mesh (the argument, else the
/// grammar's `mesh:` relative to the grammar file), and runs it.
fn subdivide(
    mesh: Option<&str>,
    grammar: &str,
    steps: Option<usize>,
    define: &[String],
) -> Result<(subgram::mesh::Mesh, usize), (u8, String)> {
    let g = subgram::surface::load_file(std::path::Path::new(grammar), define)
        .map_err(|e| (1, e.render()))?;
    let path = match (mesh, &g.mesh) {
        (Some(m), _) => std::path::PathBuf::from(m),
        (None, Some((p, _))) => {
            let rel = std::path::Path::new(grammar).parent().unwrap_or(std::path::Path::new(".")).join(p);
            if rel.exists() {
                rel
            } else {
                std::path::PathBuf::from(p)
            }
        }
        (None, None) => {
            return Err((2, format!("error: give a base mesh: `subgram subdivide MESH --grammar {grammar} ...`, or `mesh: \"file.obj\";` in the grammar")))
        }
    };
    let mut m = load_mesh(&path.display().to_string())?;
    let n = steps.or(g.length.map(|l| l as usize)).unwrap_or(1);
    if n > 12 {
        return Err((2, format!("error: {n} steps would multiply the faces by at least 2^{n}; at most 12 are allowed")));
    }
    let bar = indicatif::ProgressBar::new(n as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} step {pos}/{len} {msg} [{elapsed}]")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let result = g.run(&mut m, n, |c| {
        bar.set_position(c.step as u64);
        bar.set_message(format!(
            "{} vertices, {} edges, {} faces",
            c.vertices, c.edges, c.faces
        ));
    });
    bar.finish_and_clear();
    result.map_err(|e| (1, g.render_error(&e)))?;
    Ok((m, n))
}

/// True for a surface grammar (its text names a base mesh with `mesh:`).
fn is_surface_file(path: &str) -> bool {
    std::fs::read_to_string(path).is_ok_and(|t| subgram::surface::is_surface_text(&t))
}

fn write_mesh_picture(
    m: &subgram::mesh::Mesh,
    output: &str,
    size: (u32, u32),
    background: subgram::render::Rgba,
    view: Option<&str>,
    wireframe: bool,
) -> Result<(), (u8, String)> {
    use subgram::render::mesh::{self as draw, MeshView};
    let lower = output.to_ascii_lowercase();
    if !lower.ends_with(".png") && !lower.ends_with(".svg") {
        return Err((
            2,
            format!("error: cannot tell the format of `{output}`: name it .png or .svg"),
        ));
    }
    let mut mv = MeshView {
        width: size.0,
        height: size.1,
        background,
        wireframe,
        ..MeshView::default()
    };
    if let Some(name) = view {
        let Some((dir, up)) = draw::view_direction(name) else {
            return Err((2, format!("error: `--view {name}` is not a view of a mesh: use iso, front, back, left, right, top or bottom")));
        };
        mv.direction = dir;
        mv.up = up;
    }
    let soup = m.to_quad_soup();
    draw::validate(&soup, &mv).map_err(|e| (1, format!("error: {}", e.message)))?;
    let bytes = if lower.ends_with(".svg") {
        draw::render_svg(&soup, &mv).into_bytes()
    } else {
        draw::render_png(&soup, &mv).map_err(|e| (1, format!("error: {}", e.message)))?
    };
    write_file(output, &bytes)
}

fn write_mesh_output(
    m: &subgram::mesh::Mesh,
    output: &str,
    view: Option<&str>,
) -> Result<(), (u8, String)> {
    let lower = output.to_ascii_lowercase();
    if lower.ends_with(".png") || lower.ends_with(".svg") {
        let d = subgram::render::mesh::MeshView::default();
        return write_mesh_picture(
            m,
            output,
            (d.width, d.height),
            d.background,
            view,
            d.wireframe,
        );
    }
    subgram::mesh::io::write(std::path::Path::new(output), &m.to_quad_soup())
        .map_err(|e| (1, e.to_string()))
}

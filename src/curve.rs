//! A checked curve L-system ([`Curve`]), its runs ([`CurveRun`]) and its
//! pictures ([`FigureOptions`]).

use glam::DVec3;

use crate::draw::{self, Event};
use crate::error::Error;
use crate::lang::Program;
use crate::render;
use crate::rewrite::derive::{rule_kind, Maker, MAX_STEPS};
use crate::rewrite::growth;
use crate::rewrite::{Derivation, DeriveError, DeriveOptions, Derived, Word};
use crate::scene3::Scene3;
use crate::syntax::ast::Section;
use crate::syntax::{Diagnostic, FileId, SourceMap};

/// A checked curve L-system together with the sources its spans point into.
#[derive(Clone, Debug)]
pub struct Curve {
    pub program: Program,
    pub sources: SourceMap,
    /// What the view file beside the program sets for the turtle
    /// (rotations, tropisms); the default without one.
    pub view: draw::TurtleView,
    /// The environment of an open L-system (a model's `.e` file), started
    /// afresh for every run; runs whose options name none use it.
    pub environment: Option<std::sync::Arc<dyn crate::rewrite::environment::EnvironmentStarter>>,
}

/// Settings of a figure: how far to derive, how to draw, how to render.
#[derive(Clone, Debug, Default)]
pub struct FigureOptions {
    pub derive: DeriveOptions,
    /// Draw every step 0..=N side by side.
    pub each: bool,
    pub draw: draw::DrawOptions,
    pub render: render::RenderOptions,
}

impl Curve {
    /// The model folder's functions, contours, surfaces, colours and view
    /// settings that the program runs and is drawn with (lpfg's default
    /// circle alone for a program without a folder).
    pub fn model(&self) -> std::sync::Arc<crate::model::Model> {
        crate::model::of(&self.program)
    }

    /// Runs and draws the program with `model` instead.
    pub fn set_model(&mut self, model: crate::model::Model) {
        self.program.model = crate::lang::model::ModelRef(std::sync::Arc::new(model));
    }

    /// A derivation error as an [`Error`], located at the rule or directive
    /// at fault when there is one, else at the program's file.
    pub fn error(&self, e: DeriveError) -> Error {
        match e.span {
            Some(span) => Error::at(&self.sources, Diagnostic::new(span, e.message)),
            None => self.file_error(e.message),
        }
    }

    /// An error about the program's run as a whole: named by its file.
    fn file_error(&self, message: String) -> Error {
        Error::File {
            path: self.sources.get(FileId(0)).name.clone(),
            line: None,
            message,
        }
    }

    /// A word of step `step` that the turtle cannot draw: located at
    /// what made the module at fault, when that is known.
    fn draw_error(&self, e: draw::DrawError, step: u64, maker: Option<Maker>) -> Error {
        let message = format!("at step {step}, {}", e.message);
        let (span, made) = match maker {
            Some(Maker::Axiom(k)) => (self.program.axiom[k].span, "the axiom".to_string()),
            Some(Maker::Rule(r)) => {
                let rule = &self.program.rules[r];
                let kind = rule_kind(rule.section);
                (rule.span, format!("{kind} `{}`", rule.label))
            }
            None => return self.file_error(message),
        };
        let message = format!("{message}; {made} made that module");
        Error::at(&self.sources, Diagnostic::new(span, message))
    }

    /// A word of step `step` that the turtle cannot draw, as an [`Error`]
    /// named by the program's file (for a word drawn outside
    /// [`Curve::each_step`], which names the production too).
    pub fn drawing_error(&self, e: draw::DrawError, step: u64) -> Error {
        self.draw_error(e, step, None)
    }

    /// What made module `module` of `drawn`, the interpreted word that
    /// [`Curve::figure`] drew at step `step`: the figure's derivation run
    /// again, traced. `None` when the replay does not draw the same word.
    fn maker_in_figure(
        &self,
        opts: &FigureOptions,
        step: u64,
        drawn: &Word,
        module: usize,
    ) -> Option<Maker> {
        let mut d = Derivation::traced(&self.program, self.with_view(opts.derive.clone())).ok()?;
        d.angle().ok()?;
        let mut shown = None;
        if opts.each {
            shown = Some(d.interpret_traced().ok()?);
        }
        while d.step < step && d.has_next() {
            d.next_step().ok()?;
            if opts.each {
                shown = Some(d.interpret_traced().ok()?);
            }
        }
        if !opts.each {
            shown = Some(d.interpret_traced().ok()?);
        }
        let (word, makers) = shown?;
        if d.step != step || word != *drawn {
            return None;
        }
        makers?.get(module).copied()
    }

    /// Derives the axiom to the derivation length (or `opts.steps`) and runs
    /// `End`.
    pub fn derive(&self, opts: DeriveOptions) -> Result<Derived, Error> {
        check_steps(opts.steps)?;
        crate::rewrite::derive(&self.program, self.with_view(opts)).map_err(|e| self.error(e))
    }

    /// `opts` with this program's view file settings.
    fn with_view(&self, opts: DeriveOptions) -> DeriveOptions {
        DeriveOptions {
            queries: std::sync::Arc::new(draw::QueryTurtle {
                view: self.view.clone(),
            }),
            environment: opts.environment.or_else(|| self.environment.clone()),
            ..opts
        }
    }

    /// Derives the axiom to the derivation length (or `opts.steps`), runs
    /// `End` and keeps the derivation, so that its word can be interpreted
    /// and drawn.
    pub fn run(&self, opts: DeriveOptions) -> Result<CurveRun<'_>, Error> {
        self.run_reporting(opts, |_| {})
    }

    /// [`Curve::run`], telling `on_step` the derivation after each step
    /// (for progress: [`crate::Progress::of_derivation`]).
    pub fn run_reporting(
        &self,
        opts: DeriveOptions,
        on_step: impl FnMut(&Derivation),
    ) -> Result<CurveRun<'_>, Error> {
        check_steps(opts.steps)?;
        let mut d =
            Derivation::new(&self.program, self.with_view(opts)).map_err(|e| self.error(e))?;
        crate::production::run(&mut d, on_step).map_err(|e| self.error(e))?;
        d.end().map_err(|e| self.error(e))?;
        Ok(CurveRun { curve: self, d })
    }

    /// The derivation that [`Curve::run`] drives, started (globals set,
    /// `Start` run, the axiom decomposed) but not stepped: a caller that
    /// takes the steps itself (`has_next`, `next_step`, then `end`) gets
    /// the same word as [`Curve::run`], and may stop between steps (the
    /// Python bindings check for Ctrl-C there). Errors of the steps become
    /// [`Error`]s with [`Curve::error`].
    ///
    /// ```
    /// # fn main() -> Result<(), subgram::Error> {
    /// let root = env!("CARGO_MANIFEST_DIR");
    /// let file = format!("{root}/lsystems/curves/chaikin-13.lsys");
    /// let subgram::System::Curve(curve) = subgram::load(&file, &Default::default())? else {
    ///     unreachable!()
    /// };
    /// let opts = subgram::DeriveOptions::default().with_steps(3);
    /// let mut d = curve.derivation(opts.clone())?;
    /// while d.has_next() {
    ///     d.next_step().map_err(|e| curve.error(e))?; // or stop here
    /// }
    /// d.end().map_err(|e| curve.error(e))?;
    /// assert_eq!(d.word, *curve.run(opts)?.word());
    /// # Ok(()) }
    /// ```
    pub fn derivation(&self, opts: DeriveOptions) -> Result<Derivation<'_>, Error> {
        check_steps(opts.steps)?;
        Derivation::new(&self.program, self.with_view(opts)).map_err(|e| self.error(e))
    }

    /// `word` as text: `P([0, 0.25]) E A(1, 2)`, vectors in brackets.
    pub fn word_text(&self, word: &Word) -> String {
        crate::output::word_text(word, &self.program.alphabet, &self.program.structs)
    }

    /// [`Curve::word_text`], written to `out` as it goes.
    pub fn write_word_text(
        &self,
        out: &mut impl std::io::Write,
        word: &Word,
    ) -> std::io::Result<()> {
        crate::output::write_word_text(out, word, &self.program.alphabet, &self.program.structs)
    }

    /// [`Curve::word_json`], written to `out` as it goes.
    pub fn write_word_json(
        &self,
        out: &mut impl std::io::Write,
        word: &Word,
        ring: bool,
        step: u64,
    ) -> std::io::Result<()> {
        crate::output::write_word_json(
            out,
            word,
            ring,
            step,
            &self.program.alphabet,
            &self.program.structs,
        )
    }

    /// `word` as JSON: `{"ring": bool, "step": N, "modules": [{"symbol": "P",
    /// "params": [[0.0, 1.0]]}, …]}`.
    pub fn word_json(&self, word: &Word, ring: bool, step: u64) -> String {
        crate::output::word_json(
            word,
            ring,
            step,
            &self.program.alphabet,
            &self.program.structs,
        )
    }

    /// Derives, interprets and lays out the program's picture: its main
    /// view (see [`Curve::figures`] for the others).
    pub fn figure(&self, opts: &FigureOptions) -> Result<render::Scene, Error> {
        Ok(self.figures(opts)?.main)
    }

    /// Derives (see [`Curve::run`]) and makes the 3D geometry of the
    /// main view's interpreted word: [`CurveRun::solid`] in one call.
    pub fn solid(
        &self,
        derive: DeriveOptions,
        sopts: &draw::solid::SolidOptions,
    ) -> Result<Scene3, Error> {
        self.run(derive)?.solid(sopts)
    }

    /// Derives once and lays out the picture of every view: the main view
    /// (the interpretation rules outside any `vgroup`), and each view that
    /// `UseView` activated (the rules after its `vgroup`), in the order of
    /// their first `UseView`. With `each`, a view activated after the first
    /// step has panels from that step on.
    pub fn figures(&self, opts: &FigureOptions) -> Result<Figures, Error> {
        self.figures_reporting(opts, &mut |_| {})
    }

    /// [`Curve::figures`], telling `on_step` the derivation after each
    /// step.
    pub fn figures_reporting(
        &self,
        opts: &FigureOptions,
        on_step: &mut dyn FnMut(&Derivation),
    ) -> Result<Figures, Error> {
        let p = &self.program;
        let panels = self.each_view(
            opts,
            |_, _, word, draw_opts| draw::draw(word, &p.alphabet, &p.structs, draw_opts),
            None,
            on_step,
        )?;
        // The words are drawn and freed: each view's events are freed once
        // its picture is laid out.
        let mut scenes = Vec::with_capacity(panels.len());
        for (view, list) in panels {
            scenes.push((view, render::scene(&list, &opts.render)?));
        }
        Ok(Figures::from_views(scenes))
    }

    /// [`Curve::figures`] as PNG files' bytes, the same to the bit; each
    /// view's picture (without `each`) painted from the points the turtle
    /// keeps as it walks its word (`render::png::word`), with no events or
    /// items in memory.
    pub fn png_figures(&self, opts: &FigureOptions) -> Result<Figures<Vec<u8>>, Error> {
        self.png_figures_reporting(opts, &mut |_| {})
    }

    /// [`Curve::png_figures`], telling `on_step` the derivation after each
    /// step.
    pub fn png_figures_reporting(
        &self,
        opts: &FigureOptions,
        on_step: &mut dyn FnMut(&Derivation),
    ) -> Result<Figures<Vec<u8>>, Error> {
        if opts.each {
            return self
                .figures_reporting(opts, on_step)?
                .try_map(|s| render::png::render(s).map_err(Error::from));
        }
        let p = &self.program;
        // The main view draws the last step's word as it is (no rule
        // decomposes or interprets it): the turtle walks it on a thread of
        // its own as the step writes it.
        let as_derived = [Section::Decomposition, Section::Interpretation]
            .into_iter()
            .all(|s| p.rules_of(s).next().is_none());
        let last_step = |d: &mut Derivation, draw_opts: &draw::DrawOptions| {
            let (stepped, walked) = growth::alongside(
                |g| d.next_step_read(g),
                |g| {
                    let mut walk = render::png::WordWalk::new(
                        &p.alphabet,
                        &p.structs,
                        draw_opts,
                        opts.render.view,
                    );
                    g.read_with(&mut walk, WALK_STRIDE).then(|| walk.walked())
                },
            );
            stepped?;
            // A failed step is told before a reader that panicked.
            let walked =
                walked.and_then(|w| w.unwrap_or_else(|panic| std::panic::resume_unwind(panic)));
            // Painted on this thread, in its pool, as `draw` paints.
            Ok(walked.map(|w| w.map(|w| w.png(&opts.render))))
        };
        let painted = self.each_view(
            opts,
            // A drawing that cannot be pictured is told after every view is
            // drawn, as `figures` tells it.
            |_, _, word, draw_opts| match render::png::word(
                word,
                &p.alphabet,
                &p.structs,
                draw_opts,
                &opts.render,
            ) {
                Ok(png) => Ok(Ok(png)),
                Err(render::png::WordError::Draw(e)) => Err(e),
                Err(render::png::WordError::Render(e)) => Ok(Err(e)),
            },
            as_derived.then_some(&last_step),
            on_step,
        )?;
        let mut pictures = Vec::with_capacity(painted.len());
        for (view, mut list) in painted {
            let png = list.pop().expect("one picture a view without `each`")?;
            pictures.push((view, png));
        }
        Ok(Figures::from_views(pictures))
    }

    /// Derives once and hands `each` the main view's interpreted word of
    /// every step, 0 (the axiom) to the last, with the turtle's settings
    /// (the model, the view file's, the program's angle): `each` draws it,
    /// or returns `None` to leave the step out. A drawing that fails is
    /// told as [`Curve::figures`] tells it (the step, the module, and the
    /// production that made it). `on_step` hears after each step.
    /// Animations are made so (`command::frames`).
    pub fn each_step<T>(
        &self,
        opts: &FigureOptions,
        mut each: impl FnMut(u64, &Word, &draw::DrawOptions) -> Result<Option<T>, draw::DrawError>,
        on_step: &mut dyn FnMut(&Derivation),
    ) -> Result<Vec<T>, Error> {
        let opts = FigureOptions {
            each: true,
            ..opts.clone()
        };
        let mut drawn = self.each_view(
            &opts,
            |view, step, word, draw_opts| match view {
                0 => each(step, word, draw_opts),
                _ => Ok(None),
            },
            None,
            on_step,
        )?;
        Ok(drawn.swap_remove(0).1.into_iter().flatten().collect())
    }

    /// Derives once and draws the interpreted word of every view with
    /// `draw` (given the view and the step): the main view's drawings first, then each view's in the
    /// order of its first `UseView`; a drawing of each step with `each`
    /// (a view activated after the first step from that step on), else of
    /// the last.
    ///
    /// Without `each`, `last_step`, when given, takes the derivation's
    /// last step in place of [`Derivation::next_step`], and may draw the
    /// main view's word as it does (what `draw` would make of it), in
    /// which case `draw` does not draw it again.
    #[allow(clippy::type_complexity)]
    fn each_view<T>(
        &self,
        opts: &FigureOptions,
        mut draw: impl FnMut(i64, u64, &Word, &draw::DrawOptions) -> Result<T, draw::DrawError>,
        last_step: Option<
            &dyn Fn(
                &mut Derivation,
                &draw::DrawOptions,
            ) -> Result<Option<Result<T, draw::DrawError>>, DeriveError>,
        >,
        on_step: &mut dyn FnMut(&Derivation),
    ) -> Result<Vec<(i64, Vec<T>)>, Error> {
        check_steps(opts.derive.steps)?;
        let p = &self.program;
        let fail = |e| self.error(e);
        let mut d = Derivation::new(p, self.with_view(opts.derive.clone())).map_err(fail)?;
        let mut draw_opts = opts.draw.clone();
        draw_opts.model = crate::model::of(p);
        draw_opts.view = self.view.clone();
        if let Some(a) = d.angle().map_err(fail)? {
            draw_opts.angle = a;
        }
        let mut drawn: Vec<(i64, Vec<T>)> = vec![(0, Vec::new())];
        // `main`: the main view's drawing of the word, made as it was
        // derived.
        let mut panel = |d: &mut Derivation,
                         mut main: Option<Result<T, draw::DrawError>>|
         -> Result<(), Error> {
            let others: Vec<i64> = d.views().iter().copied().filter(|v| *v != 0).collect();
            for view in std::iter::once(0).chain(others) {
                let step = d.step;
                let word = d.interpreted_view(view).map_err(fail)?;
                let made = match main.take() {
                    Some(made) => made,
                    None => draw(view, step, &word, &draw_opts),
                };
                let made = made.map_err(|e| {
                    let maker = (e.module)
                        .filter(|_| view == 0)
                        .and_then(|m| self.maker_in_figure(opts, step, &word, m));
                    self.draw_error(e, step, maker)
                })?;
                match drawn.iter_mut().find(|(v, _)| *v == view) {
                    Some((_, list)) => list.push(made),
                    None => drawn.push((view, vec![made])),
                }
            }
            Ok(())
        };
        if opts.each {
            panel(&mut d, None)?;
        }
        let mut main = None;
        while d.has_next() {
            // A drawing made in a step that turned out not to be the last
            // is not the main view's.
            main = None;
            match last_step.filter(|_| !opts.each && d.step + 1 == d.length) {
                Some(last_step) => main = last_step(&mut d, &draw_opts).map_err(fail)?,
                None => d.next_step().map_err(fail)?,
            }
            on_step(&d);
            if opts.each {
                panel(&mut d, None)?;
            }
        }
        d.end().map_err(fail)?;
        if !opts.each {
            panel(&mut d, main)?;
        }
        Ok(drawn)
    }
}

/// The pictures of a program's views (manual 7.3): the main one, and one
/// per view that `UseView` activated, by view number.
#[derive(Clone, Debug)]
pub struct Figures<P = render::Scene> {
    pub main: P,
    pub views: Vec<(i64, P)>,
}

impl<P> Figures<P> {
    /// The pictures of views in order, the main view's first.
    fn from_views(mut views: Vec<(i64, P)>) -> Self {
        let (_, main) = views.remove(0);
        Figures { main, views }
    }

    /// Each picture made into another by `f`, the main one first; the
    /// first failure.
    pub fn try_map<Q, E>(&self, mut f: impl FnMut(&P) -> Result<Q, E>) -> Result<Figures<Q>, E> {
        Ok(Figures {
            main: f(&self.main)?,
            views: self
                .views
                .iter()
                .map(|(v, p)| Ok((*v, f(p)?)))
                .collect::<Result<_, E>>()?,
        })
    }
}

/// The turtle walking a word as it is derived walks at most this many
/// modules between looks at how far the word is written.
const WALK_STRIDE: usize = 1 << 16;

/// More steps than this are refused before a derivation starts.
fn check_steps(steps: Option<u64>) -> Result<(), Error> {
    match steps {
        Some(n) if n > MAX_STEPS => Err(Error::Usage(format!(
            "{n} steps are beyond the limit of {MAX_STEPS}"
        ))),
        _ => Ok(()),
    }
}

/// A curve L-system derived to its last step, after `End`.
pub struct CurveRun<'c> {
    curve: &'c Curve,
    d: Derivation<'c>,
}

impl<'c> CurveRun<'c> {
    /// The derived word.
    pub fn word(&self) -> &Word {
        &self.d.word
    }

    /// The number of steps performed.
    pub fn step(&self) -> u64 {
        self.d.step
    }

    /// True for a ring L-system (contexts wrap around the word).
    pub fn ring(&self) -> bool {
        self.d.ring
    }

    /// The curve that ran.
    pub fn curve(&self) -> &'c Curve {
        self.curve
    }

    /// The derived word as text.
    pub fn text(&self) -> String {
        self.curve.word_text(self.word())
    }

    /// The derived word as JSON (see [`Curve::word_json`]).
    pub fn json(&self) -> String {
        self.curve.word_json(self.word(), self.ring(), self.step())
    }

    /// The word after interpretation rules: what the turtle draws.
    pub fn interpreted(&mut self) -> Result<Word, Error> {
        let curve = self.curve;
        self.d.interpret().map_err(|e| curve.error(e))
    }

    /// What the turtle draws from the interpreted word: lines, discs,
    /// polygons, in 3D.
    pub fn events(&mut self) -> Result<Vec<Event>, Error> {
        self.drawing(|word, p, opts| draw::draw(word, &p.alphabet, &p.structs, opts))
    }

    /// The box around the turtle's lines in the interpreted word, `None`
    /// when it draws none: the extent of [`CurveRun::events`]' paths,
    /// without making them.
    pub fn line_bounds(&mut self) -> Result<Option<(DVec3, DVec3)>, Error> {
        self.drawing(|word, p, opts| draw::line_bounds(word, &p.alphabet, &p.structs, opts))
    }

    /// The 3D geometry the turtle makes from the interpreted word (tubes,
    /// surfaces, generalized cylinders, polygons, spheres, discs), one
    /// triangle mesh per colour or material of the model: see
    /// [`draw::solid`].
    pub fn solid(&mut self, sopts: &draw::solid::SolidOptions) -> Result<Scene3, Error> {
        self.drawing(|word, p, opts| draw::solid::solid(word, &p.alphabet, &p.structs, opts, sopts))
    }

    /// `walk` on the interpreted word, borrowed when no interpretation rule
    /// applies; a failure names the module and, where the replay finds it,
    /// the production that made it.
    fn drawing<T>(
        &mut self,
        walk: impl FnOnce(&Word, &Program, &draw::DrawOptions) -> Result<T, draw::DrawError>,
    ) -> Result<T, Error> {
        let curve = self.curve;
        let opts = self.draw_options()?;
        let p = &curve.program;
        let step = self.step();
        let word = self.d.interpreted_view(0).map_err(|e| curve.error(e))?;
        match walk(&word, p, &opts) {
            Ok(t) => Ok(t),
            Err(e) => {
                let word = word.into_owned();
                let maker = (e.module).and_then(|m| self.maker(&word, m));
                Err(curve.draw_error(e, step, maker))
            }
        }
    }

    /// The turtle's settings for this run: the model, the view file's, the
    /// program's angle.
    fn draw_options(&mut self) -> Result<draw::DrawOptions, Error> {
        let curve = self.curve;
        let mut opts = draw::DrawOptions {
            model: crate::model::of(&curve.program),
            view: curve.view.clone(),
            ..Default::default()
        };
        if let Some(a) = self.d.angle().map_err(|e| curve.error(e))? {
            opts.angle = a;
        }
        Ok(opts)
    }

    /// What made module `module` of `drawn`, this run's interpreted word:
    /// the derivation run again, traced. `None` when the replay does not
    /// give the same word.
    fn maker(&self, drawn: &Word, module: usize) -> Option<Maker> {
        let mut d = Derivation::traced(&self.curve.program, self.d.options().clone()).ok()?;
        crate::production::run(&mut d, |_| {}).ok()?;
        d.angle().ok()?;
        let (word, makers) = d.interpret_traced().ok()?;
        if word != *drawn {
            return None;
        }
        makers?.get(module).copied()
    }

    /// The curve's points: the turtle's lines joined into polylines, a new
    /// one wherever a line does not start where the previous one ended.
    pub fn polylines(&mut self) -> Result<Vec<Vec<DVec3>>, Error> {
        let mut lines: Vec<Vec<DVec3>> = Vec::new();
        for e in self.events()? {
            if let Event::Path { points, .. } = e {
                match lines.last_mut() {
                    Some(l) if l.last() == points.first() => l.extend_from_slice(&points[1..]),
                    _ => lines.push(points),
                }
            }
        }
        Ok(lines)
    }
}

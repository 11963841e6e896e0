//! Probes: observe every signal of every pipeline stage. A model calls its probe after each
//! stage; with [`NoProbe`] (`ON == false`) the calls compile away, so the probe costs nothing.

/// One recorded signal: a register value or a control bit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Signal<V> {
    /// A datapath register.
    Value(V),
    /// A control bit (valid, compare results).
    Flag(bool),
}

/// Receives the signals of a model, in pipeline order.
pub trait Probe<V> {
    /// False for the no-op probe, so recording code is removed at compile time.
    const ON: bool;
    /// A register value.
    fn value(&mut self, name: &'static str, v: V);
    /// A control bit.
    fn flag(&mut self, name: &'static str, b: bool);
}

/// The probe that records nothing and costs nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoProbe;

impl<V> Probe<V> for NoProbe {
    const ON: bool = false;
    #[inline(always)]
    fn value(&mut self, _: &'static str, _: V) {}
    #[inline(always)]
    fn flag(&mut self, _: &'static str, _: bool) {}
}

/// Records every signal by name, in the order the model produced them.
#[derive(Clone, Debug, Default)]
pub struct Recorder<V> {
    /// Signals in pipeline order.
    pub signals: Vec<(&'static str, Signal<V>)>,
}

impl<V: Copy> Recorder<V> {
    /// An empty recorder.
    pub fn new() -> Self {
        Self { signals: Vec::new() }
    }
    /// The signal with this name, if recorded.
    pub fn get(&self, name: &str) -> Option<Signal<V>> {
        self.signals.iter().find(|(n, _)| *n == name).map(|(_, s)| *s)
    }
    /// The register with this name, if recorded.
    pub fn value(&self, name: &str) -> Option<V> {
        match self.get(name) {
            Some(Signal::Value(v)) => Some(v),
            _ => None,
        }
    }
    /// The control bit with this name, if recorded.
    pub fn flag(&self, name: &str) -> Option<bool> {
        match self.get(name) {
            Some(Signal::Flag(b)) => Some(b),
            _ => None,
        }
    }
}

impl<V> Probe<V> for Recorder<V> {
    const ON: bool = true;
    fn value(&mut self, name: &'static str, v: V) {
        self.signals.push((name, Signal::Value(v)));
    }
    fn flag(&mut self, name: &'static str, b: bool) {
        self.signals.push((name, Signal::Flag(b)));
    }
}

/// Records named locals into a probe when it is on: `record!(p; a, b, c)`.
#[macro_export]
macro_rules! record {
    ($p:ident; $($n:ident),* $(,)?) => {
        if P::ON {
            $( $p.value(stringify!($n), $n); )*
        }
    };
}

/// Records named boolean locals into a probe when it is on.
#[macro_export]
macro_rules! record_flags {
    ($p:ident; $($n:ident),* $(,)?) => {
        if P::ON {
            $( $p.flag(stringify!($n), $n); )*
        }
    };
}

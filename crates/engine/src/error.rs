//! Why the engine refuses a program or an operation.

/// The engine's errors: a program that does not verify, native code that
/// cannot be built, a memory image of another program.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum EngineError {
    /// The program breaks an invariant the interpreter relies on.
    #[error(transparent)]
    Invalid(#[from] alba_ir::InvalidProgram),
    /// Cranelift refused the program or the host.
    #[error("{0}")]
    Native(String),
    /// Built without the feature `jit`.
    #[error("this build of Alba has no native compiler (feature `jit`)")]
    NoNativeCompiler,
    /// [`crate::Engine::load_memory`] of a memory whose regions have other
    /// sizes (bits, integers, floats, longs, doubles, bytes) than the program's.
    #[error("the memory has sizes {memory:?}, the program {program:?}")]
    MemorySizes { memory: [usize; 6], program: [usize; 6] },
    /// [`crate::Engine::run_over`] stopped at a runaway loop of backward jumps.
    #[error(
        "the run was abandoned: more than {} backward jumps",
        crate::exec::BACKWARD_JUMP_LIMIT
    )]
    Runaway,
}

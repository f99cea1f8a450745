# Shared by demo.sh and test.sh.

# Rust (stable) is the one prerequisite; everything else is built by cargo.
need_rust() {
    if ! command -v cargo >/dev/null 2>&1; then
        if [ -x "$HOME/.cargo/bin/cargo" ]; then
            export PATH="$HOME/.cargo/bin:$PATH"
        else
            echo "cargo not found: install Rust from https://rustup.rs (stable toolchain), then run this again." >&2
            exit 1
        fi
    fi
    for c in rustfmt clippy; do
        if ! cargo "${c/rustfmt/fmt}" --version >/dev/null 2>&1; then
            if command -v rustup >/dev/null 2>&1; then
                rustup component add "$c" >&2
            fi
        fi
    done
}

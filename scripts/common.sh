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

# Installs Debian packages (as root, or through sudo) when a command is missing.
# Waits up to 5 minutes for a package manager that another process holds,
# retries once (after refreshing the package lists), and on failure names the
# packages that are still missing.
apt_install() {
    local sudo=""
    if [ "$(id -u)" != 0 ]; then
        if command -v sudo >/dev/null 2>&1; then sudo="sudo"; else
            echo "need root to install $*: run 'apt-get install -y $*' as root, then run this again." >&2
            exit 1
        fi
    fi
    local lock=(-o DPkg::Lock::Timeout=300)
    echo "Installing $* (Debian packages; waiting for the package manager if it is busy)..." >&2
    local try
    for try in 1 2; do
        $sudo apt-get "${lock[@]}" update -qq >&2 || echo "apt-get update failed (try $try); going on with the package lists we have" >&2
        if DEBIAN_FRONTEND=noninteractive $sudo apt-get "${lock[@]}" install -y -qq --no-install-recommends "$@" >&2; then
            return 0
        fi
        [ "$try" = 1 ] && { echo "apt-get install $* failed; retrying once in 10 s..." >&2; sleep 10; }
    done
    local missing=() p
    for p in "$@"; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
    done
    echo "error: could not install the Debian package(s): ${missing[*]:-$*}" >&2
    echo "  try by hand: ${sudo:+sudo }apt-get install -y ${missing[*]:-$*}" >&2
    exit 1
}

# PostgreSQL server binaries (initdb, pg_ctl under /usr/lib/postgresql/*/bin): the
# shared historian's tests (crates/historian/tests/postgres.rs, alba-testkit's pg
# module) start a server of their own in a temporary directory.
need_postgres() {
    ls /usr/lib/postgresql/*/bin/pg_ctl >/dev/null 2>&1 || apt_install postgresql
}

# Mosquitto: `alba historian --mqtt`'s tests start their own broker on loopback.
need_mosquitto() {
    [ -x /usr/sbin/mosquitto ] || command -v mosquitto >/dev/null 2>&1 || apt_install mosquitto
}

# libfaketime: a test runs `alba run` under a wall clock before 1970
# (crates/cli/tests/it/clock.rs).
need_faketime() {
    ls /usr/lib/*/faketime/libfaketime.so.1 >/dev/null 2>&1 || apt_install libfaketime
}

# Node.js and npm build the browser studio (web/).
need_node() {
    if ! command -v npm >/dev/null 2>&1; then
        apt_install nodejs npm
    fi
}

# Builds the studio into web/dist (embedded into the alba binary by its build
# script); skipped when the build is newer than every source file.
build_web() {
    need_node
    (
        cd web
        if [ ! -d node_modules ] || [ package-lock.json -nt node_modules/.package-lock.json ]; then
            echo "Installing the studio's npm packages..." >&2
            npm ci --no-audit --no-fund --loglevel=error >&2
        fi
        if [ ! -f dist/index.html ] || [ -n "$(find src index.html package-lock.json vite.config.ts -newer dist/index.html -print -quit 2>/dev/null)" ]; then
            echo "Building the studio (web/dist)..." >&2
            npm run -s build >&2
        fi
    )
}

# Debian's Chromium drives the end-to-end tests (through playwright-core).
need_chromium() {
    if ! command -v chromium >/dev/null 2>&1; then
        apt_install chromium
    fi
}

# A Python virtual environment at $1 with the pinned packages of requirements
# file $2 (Debian's python3-venv when venv is missing); re-installed only
# when the requirements change.
need_pyvenv() {
    local venv="$1" req="$2"
    if ! command -v python3 >/dev/null 2>&1; then
        apt_install python3 python3-venv
    fi
    if [ ! -x "$venv/bin/python" ]; then
        python3 -m venv "$venv" 2>/dev/null || { apt_install python3-venv; python3 -m venv "$venv"; }
    fi
    if ! cmp -s "$req" "$venv/requirements.txt"; then
        echo "Installing Python packages ($req)..." >&2
        "$venv/bin/pip" install -q --disable-pip-version-check -r "$req" >&2
        cp "$req" "$venv/requirements.txt"
    fi
}

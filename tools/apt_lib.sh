# Shared by the tools/install_*.sh scripts (source it): run apt-get as root or through sudo.
#
#   apt_prepare NAME "what to install otherwise"   sets SUDO, or exits 1 with one line on stderr
#   apt_get ARGS...                                  runs "$SUDO apt-get ARGS..." non-interactively

apt_prepare() {
    local name="$1" otherwise="$2"
    if ! command -v apt-get >/dev/null 2>&1; then
        echo "$name: no apt-get here; $otherwise" >&2
        exit 1
    fi
    SUDO=""
    if [ "$(id -u)" -ne 0 ]; then
        if command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
            SUDO="sudo"
        else
            echo "$name: needs root (run as root or with sudo)" >&2
            exit 1
        fi
    fi
    export DEBIAN_FRONTEND=noninteractive
}

apt_get() {
    $SUDO apt-get "$@"
}

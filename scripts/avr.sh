# AVR toolchain for Arduino firmware (sourced after scripts/common.sh).
#   need_avr                         install avr-gcc, the Arduino AVR core, simavr and mbpoll (Debian)
#   build_board OUT                  the emulated remote-I/O board (tools/simavr/board.c)
#   build_sketch SKETCH BOARD OUTDIR build SKETCH (.cpp/.ino) for uno|nano|mega into
#                                    OUTDIR/sketch.{elf,hex}; prints flash/RAM use and
#                                    fails on a warning (-Wall -Werror) or a board that is too small

AVR_CORE=/usr/share/arduino/hardware/arduino/avr

need_avr() {
    if ! command -v avr-g++ >/dev/null 2>&1 || [ ! -d "$AVR_CORE/cores/arduino" ] \
        || ! command -v simavr >/dev/null 2>&1 || [ ! -d /usr/include/simavr ] || [ ! -f /usr/include/libelf.h ] \
        || ! command -v mbpoll >/dev/null 2>&1 || ! command -v pkg-config >/dev/null 2>&1; then
        # mbpoll (libmodbus): a third-party Modbus RTU master for the remote-I/O firmware's tests.
        apt_install gcc-avr avr-libc arduino-core-avr simavr libsimavr-dev libelf-dev pkg-config mbpoll
    fi
}

# mcu variant flash-bytes ram-bytes of a board.
avr_board() {
    case "$1" in
        uno) echo "atmega328p standard 32256 2048" ;;
        nano) echo "atmega328p eightanaloginputs 32256 2048" ;;
        mega) echo "atmega2560 mega 253952 8192" ;;
        *) echo "unknown board '$1' (uno, nano or mega)" >&2; return 1 ;;
    esac
}

build_sketch() {
    local sketch="$1" board="$2" out="$3"
    local mcu variant flash ram
    read -r mcu variant flash ram < <(avr_board "$board") || return 1
    mkdir -p "$out/core-$board"
    # Debian's gcc-avr 5.4 builds the core only as gnu++11, and its float.h
    # defines DECIMAL_DIG for C99 only (SPEC §7.3).
    local common=(-mmcu="$mcu" -DF_CPU=16000000L -DARDUINO=10807 -DARDUINO_ARCH_AVR
        -Os -Wall -ffunction-sections -fdata-sections
        -I"$AVR_CORE/cores/arduino" -I"$AVR_CORE/variants/$variant")
    local cxx=(avr-g++ "${common[@]}" -std=gnu++11 -DDECIMAL_DIG=__DECIMAL_DIG__
        -fno-exceptions -fno-threadsafe-statics -fpermissive -w)
    local cc=(avr-gcc "${common[@]}" -std=gnu11 -w)
    # The core, once per board (its own warnings are the core's, not ours: -w).
    if [ ! -f "$out/core-$board/core.a" ]; then
        local f o objs=()
        for f in "$AVR_CORE"/cores/arduino/*.c "$AVR_CORE"/cores/arduino/*.cpp "$AVR_CORE"/cores/arduino/*.S; do
            [ -f "$f" ] || continue
            o="$out/core-$board/$(basename "$f").o"
            case "$f" in
                *.cpp) "${cxx[@]}" -c "$f" -o "$o" ;;
                *.S) avr-gcc "${common[@]}" -x assembler-with-cpp -c "$f" -o "$o" ;;
                *) "${cc[@]}" -c "$f" -o "$o" ;;
            esac || return 1
            objs+=("$o")
        done
        avr-gcc-ar rcs "$out/core-$board/core.a.tmp" "${objs[@]}" || return 1
        mv "$out/core-$board/core.a.tmp" "$out/core-$board/core.a"
    fi
    # The sketch: every warning is an error.
    avr-g++ "${common[@]}" -std=gnu++11 -DDECIMAL_DIG=__DECIMAL_DIG__ -fno-exceptions \
        -fno-threadsafe-statics -Werror -x c++ -include Arduino.h -c "$sketch" -o "$out/sketch.o" || return 1
    avr-gcc -mmcu="$mcu" -Os -Wl,--gc-sections -o "$out/sketch.elf" "$out/sketch.o" "$out/core-$board/core.a" -lm || return 1
    avr-objcopy -O ihex -R .eeprom "$out/sketch.elf" "$out/sketch.hex" || return 1
    local sizes text data bss
    sizes=$(avr-size -A "$out/sketch.elf")
    text=$(awk '$1==".text"{print $2}' <<<"$sizes")
    data=$(awk '$1==".data"{print $2}' <<<"$sizes")
    bss=$(awk '$1==".bss"{print $2}' <<<"$sizes")
    local used_flash=$((text + data)) used_ram=$((data + bss))
    echo "$board: flash $used_flash of $flash bytes ($((100 * used_flash / flash))%), RAM $used_ram of $ram bytes ($((100 * used_ram / ram))%)"
    if [ "$used_flash" -gt "$flash" ] || [ "$used_ram" -gt "$ram" ]; then
        echo "error: the sketch does not fit the $board" >&2
        return 1
    fi
}

# build_harness OUT: the simavr harness (tools/simavr/harness.c), rebuilt when the source is newer.
build_harness() {
    local out="$1" src
    src="$(dirname "${BASH_SOURCE[0]}")/../tools/simavr/harness.c"
    if [ ! -x "$out" ] || [ "$src" -nt "$out" ] || [ "$(dirname "$src")/pins.h" -nt "$out" ]; then
        # shellcheck disable=SC2046
        gcc -O2 -Wall -Wextra -Werror -std=gnu11 $(pkg-config --cflags simavr) -o "$out" "$src" \
            $(pkg-config --libs simavr) -lelf
    fi
}

# build_board OUT: the emulated remote-I/O board (tools/simavr/board.c: firmware in
# simavr paced to real time, its UART on a pty), rebuilt when the source is newer.
build_board() {
    local out="$1" src
    src="$(dirname "${BASH_SOURCE[0]}")/../tools/simavr/board.c"
    if [ ! -x "$out" ] || [ "$src" -nt "$out" ] || [ "$(dirname "$src")/pins.h" -nt "$out" ]; then
        mkdir -p "$(dirname "$out")"
        # shellcheck disable=SC2046
        gcc -O2 -Wall -Wextra -Werror -std=gnu11 $(pkg-config --cflags simavr) -o "$out" "$src" \
            $(pkg-config --libs simavr) -lelf
    fi
}

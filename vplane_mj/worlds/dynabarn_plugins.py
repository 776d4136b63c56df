"""A DynaBARN plugin's animation read back from its machine code (`vplane-mj import dynabarn`).

Each `easylibobs_N.so` is DynaBARN's template compiled unoptimised for x86-64. Its
`gazebo::obs_N::Load` builds `gazebo::common::PoseAnimation(name, duration, loop)` and then, per
keyframe, calls `CreateKeyFrame(t)`, builds `Vector3<double>(x, y, z)` and hands it to
`PoseKeyFrame::Translation`, builds `Quaternion<double>(roll, pitch, yaw)` and hands it to
`PoseKeyFrame::Rotation`; last it calls `Entity::SetAnimation`. Gazebo sets the model's world
pose to the animation's interpolated keyframe at every step, so the keyframes are world positions.

The reader finds `Load` in the symbol tables (pyelftools), names each call's target by its PLT
stub and the GOT slot's relocation (or by a function symbol, for a direct call), disassembles the
function (capstone) and follows its straight-line code from the entry to the first jump or
return, emulating only the moves that carry the constants: loads of doubles from read-only data
(`movsd`, `movq`, `mov`), `mov`/`movabs` immediates, `pxor` of a register with itself (0.0),
stores to and loads from the frame's slots `[rbp - n]`, and `lea` of a slot's address. A call
forgets every register and slot, so each argument must be set between the call before and its
own; any other instruction forgets what it writes. The calls must come in the template's order
with arguments that resolve to constants, and give at least 2 finite keyframes, times from 0
strictly increasing, z 0, no rotation, a duration equal to the last keyframe's time and a loop;
else a WorldFileError names the file and what did not match. Every read is bounded: the file's
size, the counts of sections, symbols and relocations, each section inside the file, and the
function's length.
"""

from __future__ import annotations

import io
import math
import re
import struct
from dataclasses import dataclass
from pathlib import Path

import capstone
from capstone import x86
from elftools.common.exceptions import ELFError
from elftools.construct.core import ConstructError
from elftools.elf.constants import SH_FLAGS
from elftools.elf.elffile import ELFFile
from elftools.elf.enums import ENUM_RELOC_TYPE_x64
from elftools.elf.relocation import RelocationSection
from elftools.elf.sections import Section, SymbolTableSection

from vplane_mj.errors import WorldFileError

MAX_FILE_BYTES = 16 * 1024 * 1024
"""The largest plugin file read (bytes); DynaBARN's are about 185 kB."""
MAX_SECTIONS = 256
"""The most sections a plugin may have; DynaBARN's have 30."""
MAX_TABLE_ENTRIES = 100_000
"""The most entries of one symbol table or relocation section; DynaBARN's have under 1,000."""
MAX_FUNCTION_BYTES = 256 * 1024
"""The longest `Load` read (bytes), some 700 keyframes; DynaBARN's are 3 to 5 kB."""

LOAD_SYMBOL = re.compile(r"_ZN6gazebo(\d{1,4})(obs_\d+)4LoadE.+")
"""The mangled name of `gazebo::obs_N::Load(...)`; group 1 is the length of group 2."""
CALLS = {
    "animation": re.compile(r"_ZN6gazebo6common13PoseAnimationC[12]E.+db"),
    "keyframe": re.compile(r"_ZN6gazebo6common13PoseAnimation14CreateKeyFrameEd"),
    "vector": re.compile(r"_ZN8ignition4math(2v\d+)?7Vector3IdEC[12]ERKdS\d*_S\d*_"),
    "translation": re.compile(r"_ZN6gazebo6common12PoseKeyFrame11TranslationERK.+7Vector3IdEE"),
    "quaternion": re.compile(r"_ZN8ignition4math(2v\d+)?10QuaternionIdEC[12]ERKdS\d*_S\d*_"),
    "rotation": re.compile(r"_ZN6gazebo6common12PoseKeyFrame8RotationERK.+10QuaternionIdEE"),
    "set_animation": re.compile(r"_ZN6gazebo7physics(6Entity|5Model)12SetAnimationE.+"),
}
"""The template's calls, by the mangled names of their targets."""
CALL_NAMES = {
    "animation": "PoseAnimation::PoseAnimation(name, duration, loop)",
    "keyframe": "PoseAnimation::CreateKeyFrame(t)",
    "vector": "Vector3<double>::Vector3(x, y, z)",
    "translation": "PoseKeyFrame::Translation",
    "quaternion": "Quaternion<double>::Quaternion(roll, pitch, yaw)",
    "rotation": "PoseKeyFrame::Rotation",
    "set_animation": "Entity::SetAnimation",
}
NEXT_CALLS = {
    "": ("animation",),
    "animation": ("keyframe",),
    "keyframe": ("vector",),
    "vector": ("translation",),
    "translation": ("quaternion",),
    "quaternion": ("rotation",),
    "rotation": ("keyframe", "set_animation"),
}
"""The template's order: the calls that may follow each one ("": before the first)."""
ANIMATION_API = re.compile(r"_ZN6gazebo6common(13PoseAnimation|9Animation|12PoseKeyFrame|8KeyFrame)")
"""Any other call into these classes could change the animation: it is refused."""
_GOT_RELOCATIONS = (ENUM_RELOC_TYPE_x64["R_X86_64_JUMP_SLOT"], ENUM_RELOC_TYPE_x64["R_X86_64_GLOB_DAT"])
_STOPS = (capstone.CS_GRP_JUMP, capstone.CS_GRP_RET, capstone.CS_GRP_IRET, capstone.CS_GRP_INT)
"""Instruction groups that end the straight-line code."""
_MOVES = frozenset({"mov", "movabs", "movsd", "movq"})
_MASK64 = (1 << 64) - 1
_VECTOR_REGISTER = re.compile(r"[xyz]mm(\d+)")


def _gpr_parents() -> dict[str, str]:
    """Each general register's name (rax, eax, ax, al, ah, r8d, ...) -> its 64-bit register."""
    parents = {}
    for letter in "abcd":
        for name in (f"r{letter}x", f"e{letter}x", f"{letter}x", f"{letter}l", f"{letter}h"):
            parents[name] = f"r{letter}x"
    for base in ("si", "di", "bp", "sp"):
        for name in (f"r{base}", f"e{base}", base, f"{base}l"):
            parents[name] = f"r{base}"
    for number in range(8, 16):
        for name in (f"r{number}", f"r{number}d", f"r{number}w", f"r{number}b"):
            parents[name] = f"r{number}"
    return parents


_GPR = _gpr_parents()


@dataclass(frozen=True)
class PluginAnimation:
    """The animation a plugin's `Load` sets: its length (s), whether it loops, and its
    keyframes `(t_s, x_m, y_m)` in Gazebo's world frame, times from 0 strictly increasing."""

    duration_s: float
    loop: bool
    keyframes: tuple[tuple[float, float, float], ...]


@dataclass(frozen=True)
class _Slot:
    """The frame slot `[rbp + offset]` (as a value: its address)."""

    offset: int


_Value = int | _Slot
"""A tracked value: a constant's 64 bits, or a frame slot's address."""


def _disassembler() -> capstone.Cs:
    md = capstone.Cs(capstone.CS_ARCH_X86, capstone.CS_MODE_64)
    md.detail = True
    return md


def _rip_target(insn: capstone.CsInsn, operand: x86.X86Op) -> int | None:
    """The address a `[rip + disp]` memory operand names, None for any other operand."""
    if operand.type != x86.X86_OP_MEM:
        return None
    mem = operand.mem
    if mem.base != x86.X86_REG_RIP or mem.index or mem.segment:
        return None
    return (insn.address + insn.size + mem.disp) & _MASK64


class _Image:
    """One plugin's ELF file, checked and bounded; every error names `source`."""

    def __init__(self, data: bytes, source: str):
        self.data = data
        self.source = source
        self.md = _disassembler()
        if data[:4] != b"\x7fELF":
            raise self.fail("", "not an ELF file")
        elf = ELFFile(io.BytesIO(data))
        kind = (elf.elfclass, elf.little_endian, elf["e_machine"], elf["e_type"])
        if kind != (64, True, "EM_X86_64", "ET_DYN"):
            got = f"ELF{kind[0]} {'little' if kind[1] else 'big'}-endian {kind[2]} {kind[3]}"
            raise self.fail("", f"not an x86-64 shared object (ELF64 EM_X86_64 ET_DYN), got {got}")
        if elf.num_sections() > MAX_SECTIONS:
            raise self.fail("", f"has {elf.num_sections()} sections, more than {MAX_SECTIONS}")
        self.sections = [self._checked(section) for section in elf.iter_sections()]
        self.loaded = [
            section
            for section in self.sections
            if section["sh_flags"] & SH_FLAGS.SHF_ALLOC and section["sh_type"] == "SHT_PROGBITS"
        ]
        self.functions: dict[int, str] = {}
        self.loads: dict[tuple[int, int, int], str] = {}
        self._read_symbols()
        self.got_names = self._got_names()

    def fail(self, element: str, reason: str) -> WorldFileError:
        return WorldFileError(self.source, element, reason)

    def _checked(self, section: Section) -> Section:
        """The section, if its bytes lie inside the file and its table is not too long."""
        name = section.name or "a section"
        end = section["sh_offset"] + section["sh_size"]
        if section["sh_type"] != "SHT_NOBITS" and end > len(self.data):
            raise self.fail(name, f"ends at byte {end}, past the file's end ({len(self.data)} bytes)")
        if isinstance(section, SymbolTableSection | RelocationSection):
            size, length = section["sh_entsize"], section["sh_size"]
            if size <= 0 or length // size > MAX_TABLE_ENTRIES:
                reason = (
                    f"must hold at most {MAX_TABLE_ENTRIES} entries of a positive size, got {length} bytes"
                )
                raise self.fail(name, f"{reason} in entries of {size}")
        return section

    def _read_symbols(self) -> None:
        """The function symbols of the full symbol table (or, stripped, of the dynamic one):
        address -> name, and the `gazebo::obs_N::Load` functions."""
        tables = [table for table in self.sections if isinstance(table, SymbolTableSection)]
        full = [table for table in tables if table["sh_type"] == "SHT_SYMTAB"]
        for table in full or tables:
            for symbol in table.iter_symbols():
                index, address = symbol["st_shndx"], symbol["st_value"]
                if symbol["st_info"]["type"] != "STT_FUNC" or not isinstance(index, int) or not address:
                    continue
                self.functions.setdefault(address, symbol.name)
                match = LOAD_SYMBOL.fullmatch(symbol.name)
                if match and int(match.group(1)) == len(match.group(2)):
                    self.loads[(address, symbol["st_size"], index)] = match.group(2)

    def _got_names(self) -> dict[int, str]:
        """GOT slot address -> the function whose address the dynamic linker writes there."""
        names = {}
        for section in self.sections:
            if not isinstance(section, RelocationSection) or section["sh_link"] >= len(self.sections):
                continue
            table = self.sections[section["sh_link"]]
            if not isinstance(table, SymbolTableSection):
                continue
            for relocation in section.iter_relocations():
                symbol = relocation["r_info_sym"]
                if symbol and relocation["r_info_type"] in _GOT_RELOCATIONS:
                    names[relocation["r_offset"]] = table.get_symbol(symbol).name
        return names

    def load(self) -> tuple[str, int, bytes]:
        """The `Load` function: its name (`gazebo::obs_N::Load`), address and code."""
        if len(self.loads) != 1:
            found = ", ".join(sorted(set(self.loads.values()))) or "none"
            raise self.fail("", f"must define one gazebo::obs_N::Load function, found {found}")
        ((address, size, index), class_name) = next(iter(self.loads.items()))
        element = f"gazebo::{class_name}::Load"
        if not 0 < size <= MAX_FUNCTION_BYTES:
            raise self.fail(element, f"is {size} bytes long, must be 1 to {MAX_FUNCTION_BYTES}")
        section = self.sections[index] if index < len(self.sections) else None
        if section is None or self.section_at(address, size, SH_FLAGS.SHF_EXECINSTR) is not section:
            raise self.fail(element, "does not lie in an executable section")
        return element, address, self.read(section, address, size)

    def section_at(self, address: int, size: int, flag: int) -> Section | None:
        """The loaded section with the `flag` (SHF_*) whose file bytes hold [address, address + size)."""
        for section in self.loaded:
            start = section["sh_addr"]
            if (
                section["sh_flags"] & flag
                and start <= address
                and address + size <= start + section["sh_size"]
            ):
                return section
        return None

    def read(self, section: Section, address: int, size: int) -> bytes:
        offset = section["sh_offset"] + address - section["sh_addr"]
        return self.data[offset : offset + size]

    def constant(self, address: int) -> int | None:
        """The 64 bits at `address` in read-only data, None anywhere else."""
        section = self.section_at(address, 8, SH_FLAGS.SHF_ALLOC)
        if section is None or section["sh_flags"] & (SH_FLAGS.SHF_WRITE | SH_FLAGS.SHF_EXECINSTR):
            return None
        return int.from_bytes(self.read(section, address, 8), "little")

    def callee(self, insn: capstone.CsInsn) -> str | None:
        """The mangled name of the function a call goes to, None when the reader cannot tell:
        a direct call to a function symbol, a call to a PLT stub `jmp [rip + GOT slot]`, or a
        call through a GOT slot; the slot's relocation names the function."""
        if len(insn.operands) != 1:
            return None
        operand = insn.operands[0]
        slot = _rip_target(insn, operand)
        if slot is not None:
            return self.got_names.get(slot)
        if operand.type != x86.X86_OP_IMM:
            return None
        target = operand.imm & _MASK64
        if target in self.functions:
            return self.functions[target]
        section = self.section_at(target, 1, SH_FLAGS.SHF_EXECINSTR)
        if section is None:
            return None
        stub = next(self.md.disasm(self.read(section, target, 16), target), None)
        if stub is None or stub.mnemonic != "jmp" or len(stub.operands) != 1:
            return None
        slot = _rip_target(stub, stub.operands[0])
        return None if slot is None else self.got_names.get(slot)


class _Tracer:
    """Follows `Load`'s straight-line code: the tracked registers and slots, and the animation
    its calls build."""

    def __init__(self, image: _Image, element: str):
        self.image = image
        self.element = element
        self.registers: dict[str, _Value] = {}
        self.vectors: dict[str, int] = {}
        self.slots: dict[int, _Value] = {}
        self.last = ""
        self.built: _Value | None = None
        self.duration_s = math.nan
        self.loop = False
        self.keyframes: list[list[float]] = []

    def fail(self, reason: str) -> WorldFileError:
        return self.image.fail(self.element, reason)

    def trace(self, address: int, code: bytes) -> None:
        """Every instruction from the entry to the first jump or return."""
        end = address
        for insn in self.image.md.disasm(code, address):
            end = insn.address + insn.size
            if insn.group(capstone.CS_GRP_CALL):
                self.call(insn)
            elif any(insn.group(group) for group in _STOPS):
                return
            else:
                self.step(insn)
        if end < address + len(code):
            raise self.fail(f"cannot decode the instruction at {end:#x}")

    def address(self, insn: capstone.CsInsn, operand: x86.X86Op) -> _Slot | int | None:
        """Where a memory operand points: a frame slot, an absolute address ([rip + disp]), or
        None (any other base, an index or a segment)."""
        mem = operand.mem
        if mem.base == x86.X86_REG_RBP and not mem.index and not mem.segment:
            return _Slot(mem.disp)
        return _rip_target(insn, operand)

    def value(self, insn: capstone.CsInsn, operand: x86.X86Op) -> _Value | None:
        """A source operand's tracked value (64 bits, or 32 zero-extended), None if unknown."""
        if operand.type == x86.X86_OP_IMM:
            return operand.imm & _MASK64
        if operand.type == x86.X86_OP_REG:
            name = insn.reg_name(operand.reg)
            if name in _GPR:
                value = self.registers.get(_GPR[name])
                if operand.size == 4 and isinstance(value, int):
                    return value & 0xFFFFFFFF
                return value if operand.size == 8 else None
            return self.vectors.get(name)
        where = self.address(insn, operand)
        if operand.size != 8 or where is None:
            return None
        return self.slots.get(where.offset) if isinstance(where, _Slot) else self.image.constant(where)

    def set_register(self, name: str, value: _Value | None, size: int) -> None:
        """Write a register (a 32-bit write clears the upper half; a narrower one is not tracked)."""
        vector = _VECTOR_REGISTER.fullmatch(name)
        if vector:
            key = f"xmm{vector.group(1)}"
            if isinstance(value, int) and name.startswith("x"):
                self.vectors[key] = value
            else:
                self.vectors.pop(key, None)
            return
        parent = _GPR.get(name)
        if parent is None:
            return
        if parent == "rbp":
            self.slots.clear()
        if size == 4 and isinstance(value, int):
            value &= 0xFFFFFFFF
        if parent != "rbp" and value is not None and size in (4, 8):
            self.registers[parent] = value
        else:
            self.registers.pop(parent, None)

    def set_memory(self, insn: capstone.CsInsn, operand: x86.X86Op, value: _Value | None) -> None:
        """Write memory: a frame slot is tracked, a global ([rip + disp]) ignored, and a write
        anywhere else may alias any slot."""
        where = self.address(insn, operand)
        if isinstance(where, int):
            return
        if where is None:
            self.slots.clear()
            return
        stale = [offset for offset in self.slots if where.offset - 8 < offset < where.offset + operand.size]
        for offset in stale:
            del self.slots[offset]
        if operand.size == 8 and value is not None:
            self.slots[where.offset] = value

    def step(self, insn: capstone.CsInsn) -> None:
        """Emulate one instruction of the pattern, or forget whatever another one writes."""
        operands = insn.operands
        if insn.mnemonic in _MOVES and len(operands) == 2:
            target, source = operands
            value = self.value(insn, source)
            if target.type == x86.X86_OP_REG:
                self.set_register(insn.reg_name(target.reg), value, target.size)
                return
            if target.type == x86.X86_OP_MEM:
                self.set_memory(insn, target, value)
                return
        registers = len(operands) == 2 and all(operand.type == x86.X86_OP_REG for operand in operands)
        if insn.mnemonic == "pxor" and registers and operands[0].reg == operands[1].reg:
            self.set_register(insn.reg_name(operands[0].reg), 0, 16)
            return
        if insn.mnemonic == "lea" and len(operands) == 2 and operands[0].type == x86.X86_OP_REG:
            target, source = operands
            self.set_register(insn.reg_name(target.reg), self.address(insn, source), target.size)
            return
        for register in insn.regs_access()[1]:
            name = insn.reg_name(register)
            self.set_register(name, None, 0)
            if _GPR.get(name) == "rsp":
                self.slots.clear()
        for operand in operands:
            if operand.type == x86.X86_OP_MEM and operand.access & capstone.CS_AC_WRITE:
                self.set_memory(insn, operand, None)

    def call(self, insn: capstone.CsInsn) -> None:
        """A call: the template's calls read their arguments; every call forgets all state."""
        name = self.image.callee(insn)
        at = f"the call at {insn.address:#x}"
        if name is None:
            raise self.fail(f"{at} ({insn.op_str}) goes to a function the reader cannot name")
        role = next((role for role, pattern in CALLS.items() if pattern.fullmatch(name)), None)
        if role is None and ANIMATION_API.match(name):
            raise self.fail(f"{at} goes to {name}, which DynaBARN's template does not call")
        if role is not None:
            expected = NEXT_CALLS[self.last]
            if role not in expected:
                wanted = " or ".join(CALL_NAMES[call] for call in expected)
                raise self.fail(f"{at} goes to {CALL_NAMES[role]} where the template calls {wanted}")
            self.arguments(role, at)
            self.last = role
        self.registers.clear()
        self.vectors.clear()
        self.slots.clear()

    def number(self, bits: _Value | None, what: str, at: str) -> float:
        if not isinstance(bits, int):
            raise self.fail(f"{at}: {what} is not a constant")
        value = _double(bits)
        if not math.isfinite(value):
            raise self.fail(f"{at}: {what} is {value}, not a finite number")
        return value

    def pointed(self, register: str, what: str, at: str) -> float:
        """The double in the frame slot whose address `register` holds."""
        slot = self.registers.get(register)
        if not isinstance(slot, _Slot):
            raise self.fail(f"{at}: {what} ({register}) does not point at a frame slot")
        return self.number(self.slots.get(slot.offset), what, at)

    def arguments(self, role: str, at: str) -> None:
        """Read the arguments of one of the template's calls into the animation."""
        if role == "animation":
            self.duration_s = self.number(self.vectors.get("xmm0"), "the animation's duration (xmm0)", at)
            loop = self.registers.get("rdx")
            if not isinstance(loop, int):
                raise self.fail(f"{at}: the animation's loop flag (dl) is not a constant")
            self.loop = bool(loop & 0xFF)
        elif role == "keyframe":
            self.keyframes.append([self.number(self.vectors.get("xmm0"), "a keyframe's time (xmm0)", at)])
        elif role in ("vector", "quaternion"):
            names = ("x", "y", "z") if role == "vector" else ("roll", "pitch", "yaw")
            values = [
                self.pointed(register, f"a keyframe's {name}", at)
                for register, name in zip(("rsi", "rdx", "rcx"), names, strict=True)
            ]
            self.built = self.registers.get("rdi")
            if role == "vector":
                if values[2] != 0.0:
                    raise self.fail(f"{at}: a keyframe's z is {values[2]:g} m, not 0")
                self.keyframes[-1].extend(values[:2])
            elif any(values):
                angles = ", ".join(f"{value:g}" for value in values)
                raise self.fail(f"{at}: a keyframe's rotation is ({angles}) rad (roll, pitch, yaw), not zero")
        elif role in ("translation", "rotation") and (
            self.built is None or self.registers.get("rsi") != self.built
        ):
            raise self.fail(f"{at}: {CALL_NAMES[role]} is not handed the object built just before")

    def animation(self) -> PluginAnimation:
        """The animation built, checked."""
        if self.last != "set_animation":
            done = f"after {CALL_NAMES[self.last]}" if self.last else "without building a PoseAnimation"
            raise self.fail(f"ends its straight-line code {done}, not with Entity::SetAnimation")
        times = [keyframe[0] for keyframe in self.keyframes]
        if len(times) < 2:
            raise self.fail(f"sets {len(times)} keyframe: an animation needs at least 2")
        if times[0] != 0.0:
            raise self.fail(f"the first keyframe is at {times[0]:g} s, not 0")
        for index in range(1, len(times)):
            if not times[index] > times[index - 1]:
                reason = f"keyframe {index} at {times[index]:g} s does not come after {times[index - 1]:g} s"
                raise self.fail(reason)
        if self.duration_s != times[-1]:
            reason = f"the animation lasts {self.duration_s:g} s, its last keyframe is at {times[-1]:g} s"
            raise self.fail(reason)
        if not self.loop:
            raise self.fail("the animation does not loop (loop = false)")
        keyframes = tuple((t, x, y) for t, x, y in self.keyframes)
        return PluginAnimation(self.duration_s, self.loop, keyframes)


def _double(bits: int) -> float:
    """The IEEE 754 double with these 64 bits."""
    return float(struct.unpack("<d", bits.to_bytes(8, "little"))[0])


def _file_bytes(path: Path, source: str) -> bytes:
    """The file's bytes, at most MAX_FILE_BYTES."""
    try:
        with path.open("rb") as file:
            data = file.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise WorldFileError(source, "", f"cannot read the plugin: {exc.strerror or exc}") from None
    if len(data) > MAX_FILE_BYTES:
        raise WorldFileError(source, "", f"is larger than {MAX_FILE_BYTES} bytes: not a DynaBARN plugin")
    return data


def read_plugin(path: Path, source: str | None = None) -> PluginAnimation:
    """The animation that the DynaBARN plugin `path` (`easylibobs_N.so`) gives its model, read
    from the machine code of its `gazebo::obs_N::Load`; a WorldFileError naming the file
    (`source`, default the path) and what did not match when the code is not DynaBARN's template."""
    source = source or str(path)
    data = _file_bytes(path, source)
    try:
        image = _Image(data, source)
        element, address, code = image.load()
    except (ELFError, ConstructError) as exc:
        raise WorldFileError(source, "", f"not a readable ELF file (truncated or damaged?): {exc}") from None
    tracer = _Tracer(image, element)
    tracer.trace(address, code)
    return tracer.animation()

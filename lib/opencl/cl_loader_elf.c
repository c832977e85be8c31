/* The checks of a named loader file before dlopen (see cl_loader_elf.h). Every table is read
 * through the file's own offsets and sizes, each checked against the file before it is read, so
 * a hostile or damaged file can make this refuse but never fault. */
#define _POSIX_C_SOURCE 200809L
#include "opencl/cl_loader_elf.h"

#ifdef RS_CHECK_ELF
#include "core/rsmooth_internal.h"

#include <elf.h>
#include <errno.h>
#include <fcntl.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#if UINTPTR_MAX > 0xffffffffu
typedef Elf64_Ehdr elf_header;
typedef Elf64_Phdr elf_segment;
typedef Elf64_Shdr elf_section;
typedef Elf64_Dyn elf_dynamic;
typedef Elf64_Rela elf_rela;
typedef Elf64_Rel elf_rel;
#define ELF_CLASS ELFCLASS64
#define RELOCATION_TYPE(info) ELF64_R_TYPE(info)
#define RELOCATION_SYMBOL(info) ELF64_R_SYM(info)
typedef Elf64_Sym elf_symbol;
#else
typedef Elf32_Ehdr elf_header;
typedef Elf32_Phdr elf_segment;
typedef Elf32_Shdr elf_section;
typedef Elf32_Dyn elf_dynamic;
typedef Elf32_Rela elf_rela;
typedef Elf32_Rel elf_rel;
#define ELF_CLASS ELFCLASS32
#define RELOCATION_TYPE(info) ELF32_R_TYPE(info)
#define RELOCATION_SYMBOL(info) ELF32_R_SYM(info)
typedef Elf32_Sym elf_symbol;
#endif

#define MAX_SEGMENTS 64
#define MAX_DYNAMIC 1024
#define MAX_RELOCATIONS (1u << 20)
#define MAX_SLOTS 64

typedef struct library_file {
    int fd;
    uint64_t size;
    elf_segment segments[MAX_SEGMENTS];
    unsigned segment_count;
    bool text_relocations;         /* DT_TEXTREL: relocations may aim at read-only segments */
    uint64_t symbols, string_size; /* DT_SYMTAB's address, DT_STRSZ */
    /* the constructor and destructor slots (DT_INIT_ARRAY, DT_FINI_ARRAY) of a library loaded
     * anywhere hold offsets until a relocation makes them addresses: which ones one does */
    uint64_t slots[MAX_SLOTS];
    bool slot_relocated[MAX_SLOTS];
    unsigned slot_count;
} library_file;

/* The file offset of the `length` bytes at address `address`, when a loaded segment maps them
 * from the file; -1 otherwise. */
static int64_t file_offset(const library_file *f, uint64_t address, uint64_t length) {
    for (unsigned i = 0; i < f->segment_count; i++) {
        const elf_segment *s = &f->segments[i];
        if (s->p_type == PT_LOAD && address >= s->p_vaddr && length <= s->p_filesz &&
            address - s->p_vaddr <= s->p_filesz - length)
            return (int64_t)(s->p_offset + (address - s->p_vaddr));
    }
    return -1;
}

/* Whether a relocation may write `bytes` at `address`: inside a segment mapped writable (the
 * relocated read-only part, GNU_RELRO, is mapped writable until relocated). */
static bool writable(const library_file *f, uint64_t address, uint64_t bytes) {
    for (unsigned i = 0; i < f->segment_count; i++) {
        const elf_segment *s = &f->segments[i];
        if (s->p_type == PT_LOAD && (f->text_relocations || (s->p_flags & PF_W)) &&
            address >= s->p_vaddr && bytes <= s->p_memsz &&
            address - s->p_vaddr <= s->p_memsz - bytes)
            return true;
    }
    return false;
}

/* Whether the file's range [offset, offset + size) holds a run of ZERO_RUN zero bytes: what an
 * incomplete copy (a sparse or preallocated file written only in part, a zeroed block) leaves in
 * code, and what no compiler emits there (it pads with no-ops or traps). */
#define ZERO_RUN 256
static bool has_zero_run(const library_file *f, uint64_t offset, uint64_t size) {
    unsigned char block[1 << 16];
    uint64_t run = 0;
    for (uint64_t at = offset; at < offset + size;) {
        size_t n = offset + size - at < sizeof block ? (size_t)(offset + size - at) : sizeof block;
        if (!rs_pread_all(f->fd, block, n, at))
            return true;
        for (size_t i = 0; i < n; i++) {
            run = block[i] ? 0 : run + 1;
            if (run >= ZERO_RUN)
                return true;
        }
        at += n;
    }
    return false;
}

/* Whether section `sec` is one a compiler and linker fill with instructions alone: .text, .init,
 * .fini and the PLT. Other executable sections may legitimately hold zeros (libglvnd reserves a
 * zero-filled one for stubs it writes at run time). */
static bool plain_code_section(const library_file *f, const elf_section *names,
                               const elf_section *sec) {
    static const char *const known[] = {".text", ".init", ".fini", ".plt", ".plt.got", ".plt.sec"};
    char name[16] = {0};
    if (sec->sh_name >= names->sh_size ||
        !rs_pread_all(f->fd, name,
                      names->sh_size - sec->sh_name < sizeof name - 1
                          ? (size_t)(names->sh_size - sec->sh_name)
                          : sizeof name - 1,
                      names->sh_offset + sec->sh_name))
        return false;
    for (size_t k = 0; k < sizeof known / sizeof *known; k++)
        if (strcmp(name, known[k]) == 0)
            return true;
    return false;
}

/* The code, where the file has section headers (a stripped one may not: then nothing is looked
 * at): no plain code section (above) begins with zeros or holds a run of ZERO_RUN of them. */
static const char *check_code(const library_file *f, const elf_header *h) {
    static const char bad[] = "damaged (its code holds a block of zeros: an incomplete copy?)";
    elf_section names;
    if (h->e_shnum == 0 || h->e_shentsize != sizeof(elf_section) || h->e_shnum > 4096 ||
        h->e_shstrndx >= h->e_shnum ||
        (uint64_t)h->e_shoff + (uint64_t)h->e_shnum * sizeof(elf_section) > f->size ||
        !rs_pread_all(f->fd, &names, sizeof names,
                      (uint64_t)h->e_shoff + h->e_shstrndx * sizeof names) ||
        names.sh_offset > f->size || names.sh_size > f->size - names.sh_offset)
        return NULL;
    for (unsigned i = 0; i < h->e_shnum; i++) {
        elf_section sec;
        if (!rs_pread_all(f->fd, &sec, sizeof sec, (uint64_t)h->e_shoff + i * sizeof sec))
            return NULL;
        if (sec.sh_type != SHT_PROGBITS || !(sec.sh_flags & SHF_EXECINSTR) || sec.sh_size == 0 ||
            sec.sh_offset > f->size || sec.sh_size > f->size - sec.sh_offset ||
            !plain_code_section(f, &names, &sec))
            continue;
        unsigned char start[8] = {0};
        size_t n = sec.sh_size < sizeof start ? (size_t)sec.sh_size : sizeof start;
        if (!rs_pread_all(f->fd, start, n, sec.sh_offset))
            return bad;
        bool zero = true;
        for (size_t k = 0; k < n && zero; k++)
            zero = start[k] == 0;
        if (zero || has_zero_run(f, sec.sh_offset, sec.sh_size))
            return bad;
    }
    return NULL;
}

static const char *check_segments(library_file *f, const elf_header *h) {
    if (h->e_phentsize != sizeof(elf_segment) || h->e_phnum == 0 || h->e_phnum > MAX_SEGMENTS ||
        (uint64_t)h->e_phoff + (uint64_t)h->e_phnum * sizeof(elf_segment) > f->size ||
        !rs_pread_all(f->fd, f->segments, h->e_phnum * sizeof(elf_segment), h->e_phoff))
        return "truncated or damaged (its program headers lie outside the file)";
    f->segment_count = h->e_phnum;
    for (unsigned i = 0; i < f->segment_count; i++) {
        const elf_segment *s = &f->segments[i];
        if (s->p_type == PT_LOAD && (s->p_offset > f->size || s->p_filesz > f->size - s->p_offset))
            return "truncated (a loaded segment ends past the end of the file)";
    }
    return NULL;
}

/* A relocation table at `address`, `bytes` long, of `entry`-byte entries: within the file, each
 * relocation but the empty kind aimed at writable memory. */
static const char *check_relocations(library_file *f, uint64_t address, uint64_t bytes,
                                     size_t entry) {
    if (bytes == 0)
        return NULL;
    int64_t at = file_offset(f, address, bytes);
    if (at < 0 || bytes % entry != 0 || bytes / entry > MAX_RELOCATIONS)
        return "damaged (a relocation table lies outside the file)";
    for (uint64_t i = 0; i < bytes / entry; i++) {
        elf_rela r; /* a rel is a rela's first two fields */
        memset(&r, 0, sizeof r);
        if (!rs_pread_all(f->fd, &r, entry, (uint64_t)at + i * entry))
            return "truncated (a relocation cannot be read)";
        if (!writable(f, r.r_offset, sizeof(void *)))
            return "damaged (a relocation aims outside the library's writable memory)";
        for (unsigned k = 0; k < f->slot_count; k++)
            f->slot_relocated[k] |= f->slots[k] == r.r_offset;
        /* the symbol it names is read by the dynamic linker, and looked up by its name */
        uint64_t index = RELOCATION_SYMBOL(r.r_info);
        elf_symbol sym;
        int64_t sym_at = file_offset(f, f->symbols + index * sizeof sym, sizeof sym);
        if (index != 0 && (sym_at < 0 || !rs_pread_all(f->fd, &sym, sizeof sym, (uint64_t)sym_at) ||
                           sym.st_name == 0 || sym.st_name >= f->string_size))
            return "damaged (a relocation names a symbol that is missing or has no name)";
        /* linkers emit no relocations of the empty type (0): one is a zeroed table */
        if (RELOCATION_TYPE(r.r_info) == 0)
            return "damaged (its relocation table holds zeros: an incomplete copy?)";
    }
    return NULL;
}

/* The tags of the dynamic section that the checks read. */
typedef struct dynamic_tags {
    uint64_t value[DT_NUM];
    bool seen[DT_NUM];
    uint64_t gnu_hash, versym, verdef, verdefnum, verneed, verneednum;
    bool has_gnu_hash, has_versym, has_verdef, has_verneed;
} dynamic_tags;

static void record_tag(dynamic_tags *t, const elf_dynamic *e) {
    uint64_t v = e->d_un.d_val;
    if (e->d_tag >= 0 && e->d_tag < DT_NUM) {
        t->value[e->d_tag] = v;
        t->seen[e->d_tag] = true;
    } else if (e->d_tag == DT_GNU_HASH) {
        t->gnu_hash = v;
        t->has_gnu_hash = true;
    } else if (e->d_tag == DT_VERSYM) {
        t->versym = v;
        t->has_versym = true;
    } else if (e->d_tag == DT_VERDEF) {
        t->verdef = v;
        t->has_verdef = true;
    } else if (e->d_tag == DT_VERDEFNUM) {
        t->verdefnum = v;
    } else if (e->d_tag == DT_VERNEED) {
        t->verneed = v;
        t->has_verneed = true;
    } else if (e->d_tag == DT_VERNEEDNUM) {
        t->verneednum = v;
    }
}

/* The symbol hash tables the dynamic linker divides by and indexes with: their headers inside
 * the file, with buckets (a zeroed header means a division by zero in every lookup), and the GNU
 * table's Bloom filter a power of two of words with a shift below the word's bits. */
static const char *check_hash(const library_file *f, const dynamic_tags *t) {
    const char *bad = "damaged (its symbol hash table is empty or lies outside the file)";
    uint32_t words[4];
    if (t->seen[DT_HASH]) {
        int64_t at = file_offset(f, t->value[DT_HASH], 8);
        if (at < 0 || !rs_pread_all(f->fd, words, 8, (uint64_t)at) || words[0] == 0 ||
            file_offset(f, t->value[DT_HASH], 8 + 4 * ((uint64_t)words[0] + words[1])) < 0)
            return bad;
    }
    if (t->has_gnu_hash) {
        int64_t at = file_offset(f, t->gnu_hash, 16);
        /* nbuckets, symoffset, bloom_size, bloom_shift; then the filter and the buckets */
        if (at < 0 || !rs_pread_all(f->fd, words, 16, (uint64_t)at) || words[0] == 0 ||
            words[2] == 0 || (words[2] & (words[2] - 1)) != 0 || words[3] >= 8 * sizeof(void *) ||
            file_offset(f, t->gnu_hash,
                        16 + (uint64_t)words[2] * sizeof(void *) + 4 * (uint64_t)words[0]) < 0)
            return bad;
    }
    return NULL;
}

/* A chain of `count` version records (Verdef or Verneed: a record's next is at its offset
 * `next_at`, its auxiliary chain's count at `count_at` and first at `aux_at`; an auxiliary
 * record names a string at `name_at` and its next is at `aux_next_at`), each inside the file and
 * naming strings inside the string table. */
static const char *check_versions(const library_file *f, uint64_t address, uint64_t count,
                                  uint64_t string_size, int record_size, int count_at, int aux_at,
                                  int next_at, int aux_size, int name_at, int aux_next_at) {
    const char *bad = "damaged (its symbol version records lie outside the file)";
    if (count == 0 || count > 4096)
        return bad;
    for (uint64_t i = 0; i < count; i++) {
        unsigned char record[32], aux[32];
        int64_t at = file_offset(f, address, (uint64_t)record_size);
        if (at < 0 || !rs_pread_all(f->fd, record, (size_t)record_size, (uint64_t)at))
            return bad;
        uint16_t aux_count;
        uint32_t aux_offset, next;
        memcpy(&aux_count, record + count_at, 2);
        memcpy(&aux_offset, record + aux_at, 4);
        memcpy(&next, record + next_at, 4);
        uint64_t aux_address = address + aux_offset;
        for (uint16_t k = 0; k < aux_count; k++) {
            uint32_t name, aux_next;
            int64_t aux_file = file_offset(f, aux_address, (uint64_t)aux_size);
            if (aux_file < 0 || !rs_pread_all(f->fd, aux, (size_t)aux_size, (uint64_t)aux_file))
                return bad;
            memcpy(&name, aux + name_at, 4);
            memcpy(&aux_next, aux + aux_next_at, 4);
            if (name >= string_size)
                return bad;
            aux_address += aux_next;
        }
        if (i + 1 < count && next == 0)
            return bad;
        address += next;
    }
    return NULL;
}

/* The constructor and destructor slots that need a relocation: those of a library linked at
 * address 0 (loaded anywhere) that are not 0 or -1 (markers the dynamic linker skips). Too many
 * to follow: none are checked. */
static void collect_slots(library_file *f, const bool *seen, const uint64_t *value) {
    uint64_t lowest = UINT64_MAX;
    for (unsigned i = 0; i < f->segment_count; i++)
        if (f->segments[i].p_type == PT_LOAD && f->segments[i].p_vaddr < lowest)
            lowest = f->segments[i].p_vaddr;
    if (lowest != 0)
        return;
#if defined(DT_RELR) && DT_RELR < DT_NUM
    if (seen[DT_RELR]) /* packed relative relocations, not followed here */
        return;
#endif
    const int arrays[2][2] = {{DT_INIT_ARRAY, DT_INIT_ARRAYSZ}, {DT_FINI_ARRAY, DT_FINI_ARRAYSZ}};
    for (int a = 0; a < 2; a++) {
        if (!seen[arrays[a][0]])
            continue;
        uint64_t n = value[arrays[a][1]] / sizeof(void *);
        int64_t at = file_offset(f, value[arrays[a][0]], n * sizeof(void *));
        for (uint64_t k = 0; at >= 0 && k < n && f->slot_count < MAX_SLOTS; k++) {
            uintptr_t entry = 0;
            if (!rs_pread_all(f->fd, &entry, sizeof entry, (uint64_t)at + k * sizeof entry))
                continue;
            if (entry != 0 && entry != (uintptr_t)-1)
                f->slots[f->slot_count++] = value[arrays[a][0]] + k * sizeof(void *);
        }
        if (at < 0 || n > MAX_SLOTS)
            f->slot_count = 0;
    }
}

/* The dynamic section: within the file, ended, with a string table, symbols and a symbol hash
 * inside the file, its version records and relocation tables sound. */
static const char *check_dynamic(library_file *f) {
    const elf_segment *dynamic = NULL;
    for (unsigned i = 0; i < f->segment_count; i++)
        if (f->segments[i].p_type == PT_DYNAMIC)
            dynamic = &f->segments[i];
    if (!dynamic)
        return "not a dynamic library (no dynamic section)";
    uint64_t count = dynamic->p_filesz / sizeof(elf_dynamic);
    if (count == 0 || count > MAX_DYNAMIC ||
        file_offset(f, dynamic->p_vaddr, dynamic->p_filesz) < 0)
        return "damaged (its dynamic section lies outside the file)";
    elf_dynamic entries[MAX_DYNAMIC];
    if (!rs_pread_all(f->fd, entries, count * sizeof *entries, dynamic->p_offset))
        return "truncated (its dynamic section cannot be read)";
    dynamic_tags t;
    memset(&t, 0, sizeof t);
    bool ended = false;
    for (uint64_t i = 0; i < count && !ended; i++) {
        ended = entries[i].d_tag == DT_NULL;
        record_tag(&t, &entries[i]);
    }
    const uint64_t *value = t.value;
    const bool *seen = t.seen;
    if (!ended || !seen[DT_STRTAB] || !seen[DT_SYMTAB] || !seen[DT_STRSZ] || value[DT_STRSZ] == 0 ||
        !(seen[DT_HASH] || t.has_gnu_hash))
        return "damaged (its dynamic section lacks the string table, symbols or their hash, or "
               "has no end)";
    /* each relocation table whole: the dynamic linker uses what it finds of them unchecked */
    if (seen[DT_RELA] != seen[DT_RELASZ] ||
        (seen[DT_RELA] && (!seen[DT_RELAENT] || value[DT_RELAENT] != sizeof(elf_rela))) ||
        seen[DT_REL] != seen[DT_RELSZ] ||
        (seen[DT_REL] && (!seen[DT_RELENT] || value[DT_RELENT] != sizeof(elf_rel))) ||
        seen[DT_JMPREL] != seen[DT_PLTRELSZ] ||
        (seen[DT_JMPREL] &&
         (!seen[DT_PLTREL] || (value[DT_PLTREL] != DT_RELA && value[DT_PLTREL] != DT_REL))) ||
        (seen[DT_SYMENT] && value[DT_SYMENT] != sizeof(elf_symbol)))
        return "damaged (its dynamic section describes its relocations or symbols in part)";
    if (seen[DT_PLTGOT] && !writable(f, value[DT_PLTGOT], 3 * sizeof(void *)))
        return "damaged (its global offset table lies outside its writable memory)";
    const char *hash = check_hash(f, &t);
    if (hash)
        return hash;
    /* the dynamic linker reads every version record it is pointed at, without bounds */
    if ((t.has_verdef || t.has_verneed) && (!t.has_versym || file_offset(f, t.versym, 2) < 0))
        return "damaged (it has symbol versions without their table)";
    const char *versions = NULL;
    if (t.has_verdef)
        versions =
            check_versions(f, t.verdef, t.verdefnum, value[DT_STRSZ], sizeof(Elf64_Verdef),
                           offsetof(Elf64_Verdef, vd_cnt), offsetof(Elf64_Verdef, vd_aux),
                           offsetof(Elf64_Verdef, vd_next), sizeof(Elf64_Verdaux),
                           offsetof(Elf64_Verdaux, vda_name), offsetof(Elf64_Verdaux, vda_next));
    if (!versions && t.has_verneed)
        versions =
            check_versions(f, t.verneed, t.verneednum, value[DT_STRSZ], sizeof(Elf64_Verneed),
                           offsetof(Elf64_Verneed, vn_cnt), offsetof(Elf64_Verneed, vn_aux),
                           offsetof(Elf64_Verneed, vn_next), sizeof(Elf64_Vernaux),
                           offsetof(Elf64_Vernaux, vna_name), offsetof(Elf64_Vernaux, vna_next));
    if (versions)
        return versions;
    f->text_relocations = seen[DT_TEXTREL];
    f->symbols = value[DT_SYMTAB];
    f->string_size = value[DT_STRSZ];
    char last = 1;
    int64_t strings = file_offset(f, value[DT_STRTAB], value[DT_STRSZ]);
    if (strings < 0 || file_offset(f, value[DT_SYMTAB], 1) < 0 ||
        !rs_pread_all(f->fd, &last, 1, (uint64_t)strings + value[DT_STRSZ] - 1) || last != 0)
        return "damaged (its string table or symbols lie outside the file)";
    collect_slots(f, seen, value);
    const char *bad = NULL;
    if (seen[DT_RELA])
        bad = check_relocations(f, value[DT_RELA], value[DT_RELASZ], sizeof(elf_rela));
    if (!bad && seen[DT_REL])
        bad = check_relocations(f, value[DT_REL], value[DT_RELSZ], sizeof(elf_rel));
    if (!bad && seen[DT_JMPREL])
        bad = check_relocations(f, value[DT_JMPREL], value[DT_PLTRELSZ],
                                value[DT_PLTREL] == DT_REL ? sizeof(elf_rel) : sizeof(elf_rela));
    for (unsigned k = 0; !bad && k < f->slot_count; k++)
        if (!f->slot_relocated[k])
            bad = "damaged (a constructor of the library is never relocated: its relocations "
                  "are missing)";
    return bad;
}

const char *rs_check_shared_library(const char *path, char *why, size_t size) {
    if (!strchr(path, '/'))
        return NULL;
    library_file f;
    memset(&f, 0, sizeof f);
    /* O_NONBLOCK: a FIFO must not block the open */
    f.fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (f.fd < 0) {
        snprintf(why, size, "%s", strerror(errno));
        return why;
    }
    struct stat st;
    elf_header h;
    const char *bad = NULL;
    uint16_t native = 1;
    int order = *(unsigned char *)&native ? ELFDATA2LSB : ELFDATA2MSB;
    if (fstat(f.fd, &st) != 0)
        bad = strerror(errno);
    else if (!S_ISREG(st.st_mode))
        bad = S_ISDIR(st.st_mode) ? "a folder, not a library file" : "not a regular file";
    else if (!rs_pread_all(f.fd, &h, sizeof h, 0) || memcmp(h.e_ident, ELFMAG, SELFMAG) != 0)
        bad = "not an ELF file";
    else if (h.e_ident[EI_CLASS] != ELF_CLASS || h.e_ident[EI_DATA] != order)
        bad = "an ELF file of another word size or byte order than this program";
    else if (h.e_type != ET_DYN)
        bad = "not a shared library";
    if (!bad) {
        f.size = (uint64_t)st.st_size;
        bad = check_segments(&f, &h);
    }
    if (!bad)
        bad = check_dynamic(&f);
    if (!bad)
        bad = check_code(&f, &h);
    close(f.fd);
    if (bad)
        snprintf(why, size, "%s", bad);
    return bad ? why : NULL;
}
#endif

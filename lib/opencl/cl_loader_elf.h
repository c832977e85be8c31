/* What a loader file named by RSMOOTH_OPENCL_LIBRARY must be before it reaches dlopen (not
 * installed): dlopen trusts a file's structure completely, and a damaged copy of a library makes
 * it fault inside the dynamic linker (a truncated file: SIGBUS; one whose end is zeros: SIGSEGV in
 * its relocations) or block (a FIFO). Where <elf.h> is known (Linux, FreeBSD). */
#ifndef RSMOOTH_CL_LOADER_ELF_H
#define RSMOOTH_CL_LOADER_ELF_H

#include <stddef.h>

#if defined(__linux__) || defined(__FreeBSD__)
#define RS_CHECK_ELF 1
/* NULL when `path` (one with a '/': bare names are the dynamic linker's to search) is a regular
 * file holding a whole shared library of this process's class and byte order: program headers,
 * loaded segments, dynamic section, string table and relocation tables within the file, every
 * relocation aimed at memory the library maps writable. Else why not, written into `why`. */
const char *rs_check_shared_library(const char *path, char *why, size_t size);
#endif

#endif

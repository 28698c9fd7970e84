/* hash.h - FNV-1a, 64 bits: the one byte hash of the library, for fingerprints compared
 * between processes (the world's at every commit, a scene's) and the readers' tables.
 * Hash values field by field, never whole structs with padding: padding bytes may differ
 * where the values do not.
 */
#ifndef VW_CORE_HASH_H
#define VW_CORE_HASH_H

#include <stddef.h>
#include <stdint.h>

#define VW__FNV_OFFSET 0xcbf29ce484222325ull

static inline uint64_t vw__fnv1a(uint64_t h, const void *p, size_t n)
{
    const unsigned char *b = p;
    for (size_t i = 0; i < n; i++) h = (h ^ b[i]) * 0x100000001b3ull;
    return h;
}

#endif

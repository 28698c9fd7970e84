/* runtime.c - the worker loop: take the inbox, run module handlers and steps on the
 * worker's cells, route what they send; and termination by counting.
 *
 * Termination (threads engine): w->active counts busy workers plus packets in flight.
 * A packet is counted before it is queued and uncounted after it has been handled, by
 * a worker that is itself counted as busy while it handles it; a worker uncounts itself
 * only with an empty inbox, no open packets and no step work. So active == 0 means no
 * worker can ever receive anything again: global quiescence, under any interleaving
 * or delay. Whoever brings it to zero wakes everybody.
 *
 * Under MPI the same count covers this process only: the transport's communication
 * thread (the thread that called run) holds one extra count, so workers never end the
 * run on local quiescence; it gives the count back once all processes agree (see
 * transport/mpi.c). The threads engine has no such thread and never polls.
 *
 * The worker threads are a pool kept for the world's life (pool_start, pool_dispatch,
 * pool_wait): a run or a build is a job every worker does once, so an iterative
 * solver's hundreds of runs start no threads, and each worker stays on its CPU.
 */
#include "core/world_internal.h"
#include "vwalls/engine.h"

#include <math.h>
#include <sched.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

struct vw_ctx {
    vw_world *w;
    vw__worker *wk;
    int cell;
    int rep; /* which copy of the cell: 0 = the master */
    /* The unit the runtime called the module for: the module hands off inline from it
       (vw_ctx_enter) and restores it, which then needs no check that this worker
       hosts it. */
    int home_cell, home_rep;
    /* 1 in the worker loop (messages, steps); 0 in cell_build and load, which run outside
       the meter's windows: a hand-off there is refused, for the meter would keep the
       note across runs (and a new decomposition freeing the cell), and charge it the
       time since its last clock read. */
    int in_run;
    /* The hand-off's fast path (vw_ctx_enter, vw_ctx_restore), one compare per rare case
       it leaves to the slow path: enter_cells is the number of cells in a run without
       the stress switch, 0 otherwise (so every hand-off takes the slow path, which
       checks all); `handled` has bit k set when kind k has a handle (bits past the
       module's kinds clear); cells and global are w->cells and wk->global. */
    unsigned enter_cells;
    int global;
    vw__cell *cells;
    uint64_t handled;
};

/* The kinds of the module that have a handle, one bit each (VW_MAX_KINDS is 64). */
static uint64_t handled_kinds(const vw_module *m)
{
    uint64_t b = 0;
    for (int k = 0; k < m->nkinds && k < 64; k++)
        if (m->kinds[k].handle) b |= (uint64_t)1 << k;
    return b;
}

/* The module's callbacks may run from now until callbacks_end (w->in_callbacks): a
   world-changing call meanwhile is refused (vw__world_guard). Returns what was running
   them before (a load() called from a query made in a handler), to restore. */
static const char *callbacks_begin(vw_world *w, const char *what)
{
    return atomic_exchange(&w->in_callbacks, what);
}

static void callbacks_end(vw_world *w, const char *before) { atomic_store(&w->in_callbacks, before); }

void vw__world_reentered(const vw_world *w, const char *call)
{
    fprintf(stderr, "vwalls: module '%s' called %s from a callback during %s: the world "
                    "changes, and its processes agree, only between runs (a callback sends "
                    "messages instead)\n",
            w->m->name ? w->m->name : "?", call, atomic_load(&w->in_callbacks));
    abort();
}

/* The figures and state of copy rep of a cell (0: the master itself). */
static void **unit_state(vw_world *w, int cell, int rep)
{
    return rep ? &w->cells[cell].reps[rep - 1].state : &w->cells[cell].state;
}

static int64_t *unit_counters(vw_world *w, int cell, int rep)
{
    return rep ? w->cells[cell].reps[rep - 1].counters : w->cells[cell].counters;
}

double vw__now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

uint64_t vw__rng_next(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static size_t msg_stride(size_t size) { return sizeof(vw__msg_header) + ((size + 7) & ~(size_t)7); }

vw__packet *vw__packet_new(int dest, int src, size_t cap)
{
    vw__packet *p = malloc(sizeof *p + cap);
    if (!p) return NULL;
    p->next = NULL;
    p->dest = dest;
    p->src = src;
    p->nmsgs = 0;
    p->used = 0;
    p->cap = cap;
    return p;
}

/* ---- a failed run -------------------------------------------------------------------- */

static void run_fail_v(vw_world *w, vw_status st, const char *fmt, va_list ap)
{
    if (st == VW_OK) st = VW_E_STATE; /* a failure must not read as success */
    int expected = 0;
    if (atomic_compare_exchange_strong(&w->run_failed, &expected, 1)) {
        vsnprintf(w->run_msg, sizeof w->run_msg, fmt, ap);
        w->run_err = st;
    }
    atomic_store(&w->dropping, 1);
}

void vw__run_fail(vw_world *w, vw_status st, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    run_fail_v(w, st, fmt, ap);
    va_end(ap);
}

static inline int dropping(const vw_world *w)
{
    return atomic_load_explicit(&w->dropping, memory_order_relaxed);
}

/* ---- delivery ---------------------------------------------------------------------- */

static void finish_run(vw_world *w)
{
    atomic_store(&w->finished, 1);
    for (int i = 0; i < w->nworkers; i++) {
        pthread_mutex_lock(&w->workers[i].mu);
        pthread_cond_broadcast(&w->workers[i].cv);
        pthread_mutex_unlock(&w->workers[i].mu);
    }
}

void vw__uncount(vw_world *w)
{
    if (atomic_fetch_sub(&w->active, 1) == 1) finish_run(w);
}

void vw__run_output(vw_world *w, const vw__packet *p)
{
    pthread_mutex_lock(&w->output_mu);
    size_t off = 0;
    for (uint32_t i = 0; i < p->nmsgs && !dropping(w); i++) {
        const vw__msg_header *h = (const vw__msg_header *)(p->data + off);
        const vw_msg_kind *k = &w->m->kinds[h->kind];
        if (k->output) k->output(w->user, p->data + off + sizeof *h);
        off += msg_stride(h->size);
    }
    pthread_mutex_unlock(&w->output_mu);
}

/* Hands a full or flushed packet to its destination. The packet is counted in
   w->active first, so quiescence cannot be declared while it is on its way. */
void vw__deliver(vw_world *w, vw__worker *from, vw__packet *p)
{
    if (from) {
        from->packets_sent++;
        from->msgs_sent += p->nmsgs;
        from->bytes_sent += p->used;
    }
    if (w->transport && (p->dest == VW__OUTPUT ? w->rank != 0
                                               : vw__worker_process(w, p->dest) != w->rank)) {
        if (from) {
            from->msgs_remote += p->nmsgs;
            from->bytes_remote += p->used;
        }
        w->transport->send(w, from, p);
        return;
    }
    if (p->dest == VW__OUTPUT) {
        /* Output packets are handled at once by the output process's lock: they create
           no work, so they need no counting. */
        vw__run_output(w, p);
        free(p);
        return;
    }
    if (from) atomic_fetch_add(&from->outstanding, vw__packet_charge(p));
    vw__deliver_local(w, p, from ? &from->rng : NULL);
}

void vw__deliver_local(vw_world *w, vw__packet *p, uint64_t *rng)
{
    vw__worker *to = &w->workers[p->dest - w->rank * w->nworkers];
    atomic_fetch_add(&w->active, 1);
    pthread_mutex_lock(&to->mu);
    if (w->cfg.stress_seed && rng && to->head && (vw__rng_next(rng) & 1)) {
        /* Stress: insert at a random place, so packets overtake each other. */
        uint64_t n = vw__rng_next(rng) % 8;
        vw__packet **at = &to->head;
        while (*at && n--) at = &(*at)->next;
        p->next = *at;
        *at = p;
        if (!p->next) to->tail = p;
    } else {
        p->next = NULL;
        if (to->tail)
            to->tail->next = p;
        else
            to->head = p;
        to->tail = p;
    }
    pthread_cond_signal(&to->cv);
    pthread_mutex_unlock(&to->mu);
}

const char *vw__packet_problem(const vw_world *w, const vw__packet *p, char *buf, size_t len)
{
    size_t off = 0;
    for (uint32_t i = 0; i < p->nmsgs; i++) {
        if (p->used - off < sizeof(vw__msg_header)) {
            snprintf(buf, len, "message %u of %u lies past its %zu bytes", i, p->nmsgs, p->used);
            return buf;
        }
        const vw__msg_header *h = (const vw__msg_header *)(p->data + off);
        if (h->kind >= w->m->nkinds || h->size != w->m->kinds[h->kind].size) {
            snprintf(buf, len, "message %u is of kind %u with %u bytes (module '%s' has %d kinds)",
                     i, (unsigned)h->kind, (unsigned)h->size, w->m->name, w->m->nkinds);
            return buf;
        }
        if (p->dest != VW__OUTPUT && (h->cell < 0 || h->cell >= w->ncells)) {
            snprintf(buf, len, "message %u is for cell %d of %d", i, (int)h->cell, w->ncells);
            return buf;
        }
        size_t stride = msg_stride(h->size);
        if (stride > p->used - off) {
            snprintf(buf, len, "message %u runs past the packet's %zu bytes", i, p->used);
            return buf;
        }
        off += stride;
    }
    if (off != p->used) {
        snprintf(buf, len, "its %u messages fill %zu of its %zu bytes", p->nmsgs, off, p->used);
        return buf;
    }
    return NULL;
}

static int flush_all(vw__worker *wk)
{
    vw_world *w = wk->w;
    int any = 0;
    for (int d = 0; d <= w->gworkers; d++) {
        vw__packet *p = wk->out[d];
        if (p && p->nmsgs) {
            wk->out[d] = NULL;
            vw__deliver(w, wk, p);
            any = 1;
        }
    }
    return any;
}

/* A module's misuse of the context is a bug in the module: it stops the process. The
   line is written whole by one write(2), and by the first worker only: when several
   made the same mistake at once, their pieces were interleaved on the terminal and the
   first abort cut the others short. The others wait for that abort. */
static void __attribute__((noreturn, noinline, cold, format(printf, 2, 3)))
misuse(const vw_ctx *ctx, const char *fmt, ...)
{
    static int reported;
    if (__atomic_exchange_n(&reported, 1, __ATOMIC_ACQ_REL))
        for (;;) pause();
    char line[512], what[320];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    int n = snprintf(line, sizeof line, "vwalls: module '%s' %s (worker %d, in cell %d)\n",
                     ctx->w->m->name, what, ctx->wk->global, ctx->cell);
    if (n > (int)sizeof line - 1) n = (int)sizeof line - 1;
    if (n > 0 && write(STDERR_FILENO, line, (size_t)n) < 0) { /* nothing more to tell */ }
    abort();
}

/* Only a signal (a kind of size 0) may be sent without a buffer: memcpy read address 0.
   Every send that reaches a cell is checked in enqueue; one that reaches nobody (a point
   outside, a face on the world's wall) is checked where it ends, so the mistake shows on
   the first send, wherever the cell lies. */
static inline void check_msg(const vw_ctx *ctx, int kind, const void *msg)
{
    const vw_module *m = ctx->w->m;
    if (!msg && kind >= 0 && kind < m->nkinds && m->kinds[kind].size)
        misuse(ctx, "sent message kind %d of %d bytes with no message (NULL)", kind,
               (int)m->kinds[kind].size);
}

static void enqueue(vw_ctx *ctx, int slot, int dest, int cell, int kind, const void *msg)
{
    vw_world *w = ctx->w;
    vw__worker *wk = ctx->wk;
    if (kind < 0 || kind >= w->m->nkinds)
        misuse(ctx, "sent unknown message kind %d (it has %d kinds)", kind, w->m->nkinds);
    /* cell_build and load run between runs: a packet opened there was flushed at the
       next run, to the worker that hosted the cell at the build (a remap since, and it
       received a message for a cell it no longer hosts). */
    if (!ctx->in_run)
        misuse(ctx, "sent message kind %d from cell %d outside a run (cell_build or load)", kind,
               ctx->cell);
    size_t size = w->m->kinds[kind].size;
    check_msg(ctx, kind, msg);
    size_t stride = msg_stride(size);
    vw__packet *p = wk->out[slot];
    if (p && p->used + stride > p->cap) {
        wk->out[slot] = NULL;
        vw__deliver(w, wk, p);
        p = NULL;
    }
    if (!p) {
        size_t cap = w->cfg.stress_split ? stride
                                         : (w->cfg.packet_bytes > stride ? w->cfg.packet_bytes : stride);
        p = vw__packet_new(dest, wk->global, cap);
        if (!p) {
            /* The message is lost, so the run is failed: nothing was counted for it. */
            vw__run_fail(w, VW_E_NOMEM, "worker %d: out of memory for a %zu-byte packet",
                         wk->global, cap);
            return;
        }
        wk->out[slot] = p;
    }
    if (dest != VW__OUTPUT) {
        /* Traffic by destination class, for the mapping's locality figures. */
        if (dest == wk->global) wk->tr_self_msgs++, wk->tr_self_bytes += stride;
        int dp = vw__worker_process(w, dest);
        wk->tr_proc[2 * dp]++;
        wk->tr_proc[2 * dp + 1] += stride;
    }
    vw__msg_header *h = (vw__msg_header *)(p->data + p->used);
    h->cell = cell;
    h->kind = (uint16_t)kind;
    h->size = (uint16_t)size;
    /* A kind of size 0 is a signal: its msg may be NULL, which memcpy may not get. */
    if (size) memcpy(p->data + p->used + sizeof *h, msg, size);
    p->used += stride;
    p->nmsgs++;
    if (w->cfg.stress_split) {
        wk->out[slot] = NULL;
        vw__deliver(w, wk, p);
    }
}

/* Under MPI, when the workers take every core the process may run on (a launcher that
   binds a process to one core, and one worker on it), the communication thread has no
   core of its own: a busy worker gives its core away for a moment every 200 us, so the
   communication thread runs then instead of waiting for the kernel to preempt the
   worker (about 3.7 ms here), and a turn request or a packet from another process is
   answered in time (w->share_core). Not with a core to spare: on an oversubscribed
   machine a yield hands the core to other processes' busy threads too. */
static void share_core(vw__worker *wk)
{
    double now = vw__now();
    if (now - wk->yielded < 200e-6) return;
    wk->yielded = now;
    sched_yield();
}

/* ---- the meter: busy time per cell ---------------------------------------------------- */

/* Every unit (cell, or copy of a duplicated cell) is charged the time the worker spent
   running its callbacks: the balancer's measured load. The clock is read when the
   worker switches unit by message or step; an inline hand-off (vw_ctx_enter) only
   notes the unit it enters, because a clock read (28 ns here) costs as much as the ray
   segment it would time. The time since the last read is shared evenly among the notes
   since (a unit noted k times gets k shares), and read again once VW__METER_N are
   noted; without hand-offs a unit is charged exactly the time between its switches.
   A note is a count on the unit, which joins the worker's list of units at its first
   note: the list has each unit once, however often a ray passes back and forth. */
static void meter_charge(vw__worker *wk, double now)
{
    vw_world *w = wk->w;
    double dt = now - wk->mark;
    const double *s = w->cfg.worker_slowdown;
    if (s && s[wk->global] > 1.0) {
        /* An emulated slower machine: spin for (k-1) times the time spent, charged too;
           giving the core away as a busy worker does (share_core), or the emulated
           machine's communication thread would answer later than a real one's. */
        double until = now + dt * (s[wk->global] - 1.0);
        while ((now = vw__now()) < until)
            if (w->share_core) share_core(wk);
        dt = now - wk->mark;
    }
    wk->busy_s += dt;
    double share = wk->nnotes > 1 ? dt / wk->nnotes : dt;
    for (int i = 0; i < wk->nmetered; i++) {
        vw__busy *u = wk->metered[i];
        u->s += u->notes == 1 ? share : share * u->notes;
        u->notes = 0;
    }
    wk->mark = now;
    wk->nmetered = wk->nnotes = 0;
}

/* The busy time of unit (cell, rep), or the worker's `idle` for no unit (cell < 0). */
static vw__busy *unit_busy(vw__worker *wk, int cell, int rep)
{
    vw_world *w = wk->w;
    if (cell < 0) return &wk->idle;
    return rep ? &w->cells[cell].reps[rep - 1].busy : &w->cells[cell].busy;
}

/* Notes that unit u runs (an inline hand-off, or a switch): timed with the next clock
   read. At most VW__METER_N notes, so the list of distinct units cannot overflow. A full
   list is charged before u is noted, never after: u runs from now on, and charged after,
   the list was empty and the time until the next read belonged to no unit. */
static inline void meter_note(vw__worker *wk, vw__busy *u)
{
    if (wk->nnotes == VW__METER_N) meter_charge(wk, vw__now());
    if (u->notes++ == 0) wk->metered[wk->nmetered++] = u;
    wk->nnotes++;
}

/* The worker starts running unit (cell, rep): what ran before is charged. */
static void meter_switch(vw__worker *wk, int cell, int rep)
{
    meter_charge(wk, vw__now());
    meter_note(wk, unit_busy(wk, cell, rep));
}

/* Starts the meter on unit (cell, rep), the time before uncharged (inbox, idle). */
static void meter_start(vw__worker *wk, int cell, int rep)
{
    for (int i = 0; i < wk->nmetered; i++) wk->metered[i]->notes = 0;
    wk->nmetered = wk->nnotes = 0;
    wk->mark = vw__now();
    meter_note(wk, unit_busy(wk, cell, rep));
}

static void meter_stop(vw__worker *wk) { meter_charge(wk, vw__now()); }

/* ---- the module's side: vw_ctx ------------------------------------------------------ */

int vw_ctx_cell(const vw_ctx *ctx) { return ctx->cell; }
int vw_ctx_worker(const vw_ctx *ctx) { return ctx->wk->global; }
int vw_ctx_process(const vw_ctx *ctx) { return ctx->w->rank; }
const vw_decomp *vw_ctx_decomp(const vw_ctx *ctx) { return ctx->w->decomp; }
vw_box vw_ctx_cell_box(const vw_ctx *ctx) { return vw_decomp_cell_box(ctx->w->decomp, ctx->cell); }
void *vw_ctx_user(const vw_ctx *ctx) { return ctx->w->user; }
int vw_ctx_replica(const vw_ctx *ctx) { return ctx->rep; }
int vw_ctx_replicas(const vw_ctx *ctx)
{
    return ctx->cell >= 0 ? ctx->w->cells[ctx->cell].nreps : 0;
}

/* The batch of unit u's i-th turn: of its i-th slot in the cell's share pattern (u + k i
   with equal speeds), or nbatches when that is past the end. */
static uint64_t turn_batch(const vw__cell *c, int u, uint64_t i, uint64_t nbatches)
{
    if (i >= nbatches) return nbatches; /* a unit's i-th slot is never before slot i */
    if (!c->share_len) return i;        /* no copies: 0, 1, 2, ... */
    uint64_t L = (uint64_t)c->share_len, n = (uint64_t)(c->share_first[u + 1] - c->share_first[u]);
    uint64_t q = i / n;
    if (q > (UINT64_MAX - L) / L) return nbatches;
    uint64_t b = q * L + (uint64_t)c->share_pos[c->share_first[u] + (int)(i % n)];
    return b < nbatches ? b : nbatches;
}

/* The next of unit u's turns (i = 0, 1, ...: its counter), or nbatches when they are
   used up. One atomic add per batch: every value of the counter goes to one taker. */
static uint64_t take_turn(const vw__cell *c, _Atomic uint64_t *counter, int u, uint64_t nbatches)
{
    return turn_batch(c, u, atomic_fetch_add_explicit(counter, 1, memory_order_relaxed), nbatches);
}

/* How many turns unit u has in all: its slots before nbatches. */
static uint64_t turns_of(const vw__cell *c, int u, uint64_t nbatches)
{
    if (!c->share_len) return nbatches;
    uint64_t L = (uint64_t)c->share_len;
    int first = c->share_first[u], n = c->share_first[u + 1] - first;
    uint64_t t = nbatches / L * (uint64_t)n;
    for (int j = 0; j < n; j++) t += (uint64_t)c->share_pos[first + j] < nbatches % L;
    return t;
}

static _Atomic uint64_t *turn_counter(vw__cell *c, int u)
{
    return u ? &c->reps[u - 1].batches : &c->batches;
}

uint64_t vw__take_turns(vw_world *w, int cell, int unit, int thief, uint64_t nbatches,
                        uint64_t *first)
{
    if ((unsigned)cell >= (unsigned)w->ncells || (unsigned)thief >= (unsigned)w->gworkers)
        return UINT64_MAX;
    vw__cell *c = &w->cells[cell];
    if (unit < 0 || unit > c->nreps) return UINT64_MAX;
    int worker = unit ? c->reps[unit - 1].worker : c->worker;
    if (vw__worker_process(w, worker) != w->rank) return UINT64_MAX;
    _Atomic uint64_t *counter = turn_counter(c, unit);
    uint64_t all = turns_of(c, unit, nbatches), at = atomic_load_explicit(counter, memory_order_relaxed);
    *first = at;
    if (at >= all) return 0;
    /* The thief's part of what is left, by the two workers' speeds: half when they are
       equal (or unknown), so that both would end together. */
    double part = w->speeds ? w->speeds[thief] / (w->speeds[thief] + w->speeds[worker]) : 0.5;
    double want = ceil((double)(all - at) * part);
    uint64_t k = want < 1 ? 1 : want >= (double)(all - at) ? all - at : (uint64_t)want;
    /* One add for all k: the unit's own worker goes on after them. Those past its
       last turn (its worker took some meanwhile) are none: the thief stops there. */
    *first = atomic_fetch_add_explicit(counter, k, memory_order_relaxed);
    return k;
}

/* The next turn of the unit's stash, or nbatches when it is empty; counted as the
   worker's turns of other processes' copies. */
static uint64_t stash_next(vw__worker *wk, const vw__cell *c, vw__stash *s, uint64_t nbatches)
{
    while (s->at < s->end) {
        uint64_t b = turn_batch(c, s->unit, s->at++, nbatches);
        if (b < nbatches) {
            wk->turns_remote++;
            return b;
        }
        s->at = s->end; /* a unit's turns only grow: none after one past the end */
    }
    return nbatches;
}

/* Turns of unit u from its process, which holds the counter: a round trip through the
   communication threads for the thief's part of what u has left, kept in the asking
   unit's stash. The worker's wait is nobody's busy time. */
static uint64_t take_remote_turns(vw_ctx *ctx, int u, uint64_t nbatches, vw__stash *stash)
{
    vw__worker *wk = ctx->wk;
    meter_charge(wk, vw__now());
    uint64_t first = 0, n = ctx->w->transport->take_turns(ctx->w, ctx->cell, u, wk->global,
                                                             nbatches, &first);
    wk->mark = vw__now();
    meter_note(wk, unit_busy(wk, ctx->cell, ctx->rep));
    *stash = (vw__stash){u, first, first + n};
    return stash_next(wk, &ctx->w->cells[ctx->cell], stash, nbatches);
}

uint64_t vw_ctx_next_batch(vw_ctx *ctx, uint64_t nbatches)
{
    if (ctx->cell < 0) return nbatches;
    vw_world *w = ctx->w;
    vw__cell *c = &w->cells[ctx->cell];
    int k = c->nreps + 1;
    vw__stash *stash = ctx->rep ? &c->reps[ctx->rep - 1].stash : &c->stash;
    uint64_t b = stash_next(ctx->wk, c, stash, nbatches);
    if (b < nbatches) return b;
    b = take_turn(c, turn_counter(c, ctx->rep), ctx->rep, nbatches);
    if (b < nbatches || k == 1 || !w->steal) return b;
    /* Its own turns used up, a copy takes the turns the other copies have not taken yet:
       a copy whose worker the machine slowed down leaves its rest to the copies that are
       done, instead of everyone waiting for it (vw_config.steal says when). First those
       of this process, one at a time by an add on their counters; then those of the
       other processes, whose counters live there, by asking: a round trip for the
       thief's part of what the copy has left (vw__take_turns), and only once every copy
       here is done; a copy that answered "none left" is not asked again this run. */
    for (int i = 1; i < k; i++) {
        int u = (ctx->rep + i) % k;
        int worker = u ? c->reps[u - 1].worker : c->worker;
        if (vw__worker_process(w, worker) != w->rank) continue;
        b = take_turn(c, turn_counter(c, u), u, nbatches);
        if (b < nbatches) return b;
    }
    if (!w->transport) return nbatches;
    for (int i = 1; i < k; i++) {
        int u = (ctx->rep + i) % k;
        int worker = u ? c->reps[u - 1].worker : c->worker;
        atomic_int *spent = u ? &c->reps[u - 1].spent : &c->spent;
        if (vw__worker_process(w, worker) == w->rank ||
            atomic_load_explicit(spent, memory_order_relaxed))
            continue;
        b = take_remote_turns(ctx, u, nbatches, stash);
        if (b < nbatches) return b;
        atomic_store_explicit(spent, 1, memory_order_relaxed);
    }
    return nbatches;
}

/* Which copy of duplicated cell c this worker may hand a message of `kind` to inline,
   or -1. When every worker of this process holds one (farming), this worker's own copy
   takes it, and a ray stays on the worker it started on; otherwise the copies share
   what is sent to the cell in turns, the shares the balancer planned. */
static int enter_copy(const vw_ctx *ctx, int cell, int kind)
{
    const vw_world *w = ctx->w;
    if (!w->cells[cell].farmed || !(w->m->kinds[kind].flags & VW_MSG_INDEPENDENT)) return -1;
    return vw__cell_rep_of(w, cell, ctx->wk->global);
}

/* vw_ctx_enter's every case: what the fast path leaves (a cell or kind that does not
   exist or has no handle, a duplicated cell, a cell of another worker, outside a run,
   the stress switch). */
static void *__attribute__((noinline)) enter_slow(vw_ctx *ctx, int cell, int kind)
{
    vw_world *w = ctx->w;
    if ((unsigned)cell >= (unsigned)w->ncells || (unsigned)kind >= (unsigned)w->m->nkinds)
        misuse(ctx, "entered cell %d with message kind %d: no such cell or kind", cell, kind);
    if (!w->m->kinds[kind].handle)
        misuse(ctx, "entered cell %d with message kind %d ('%s'), but the kind has no handle "
               "(an output kind: sent with vw_send_output)", cell, kind, w->m->kinds[kind].name);
    if (!ctx->in_run) return NULL;
    vw__cell *c = &w->cells[cell];
    int rep = 0;
    if (c->nreps) {
        rep = enter_copy(ctx, cell, kind);
        if (rep < 0) return NULL;
    } else if (w->cell_worker[cell] != ctx->wk->global) {
        return NULL;
    }
    /* Stress: refuse half the hand-offs, so both paths run under every interleaving. */
    if (w->cfg.stress_seed && (vw__rng_next(&ctx->wk->rng) & 1)) return NULL;
    void *state;
    int noted = cell != ctx->cell || ctx->rep != rep;
    if (rep) {
        vw__replica *r = &c->reps[rep - 1];
        if (noted) meter_note(ctx->wk, &r->busy);
        r->messages_in++;
        state = r->state;
    } else {
        if (noted) meter_note(ctx->wk, &c->busy);
        c->messages_in++;
        state = c->state;
    }
    ctx->cell = cell;
    ctx->rep = rep;
    return state;
}

/* The common case, small enough to be inlined into the module's walk (LTO): a cell of
   this worker without copies, in a run without the stress switch, for a kind with a
   handle. Each of the other cases fails one of the first two tests (enter_cells is 0
   outside a run and under the stress switch) or the third, and the slow path decides
   it as it always did. The master of a cell without copies is the only unit of it this
   worker can be in, so the cell alone says whether the meter notes it. */
void *vw_ctx_enter(vw_ctx *ctx, int cell, int kind)
{
    if ((unsigned)cell < ctx->enter_cells && (unsigned)kind < 64 && (ctx->handled >> kind & 1)) {
        vw__cell *c = &ctx->cells[cell];
        if (c->solo == ctx->global) {
            if (cell != ctx->cell) meter_note(ctx->wk, &c->busy);
            c->messages_in++;
            ctx->cell = cell;
            ctx->rep = 0;
            return c->state;
        }
    }
    return enter_slow(ctx, cell, kind);
}

/* vw_ctx_restore's every case: what the fast path leaves (a copy, a cell of another
   worker or none, outside a run, the stress switch). */
static void __attribute__((noinline)) restore_slow(vw_ctx *ctx, int cell, int replica)
{
    if (cell != ctx->home_cell || replica != ctx->home_rep) {
        vw_world *w = ctx->w;
        int hosted = cell >= 0 && cell < w->ncells &&
                     (replica == 0 ? w->cell_worker[cell] == ctx->wk->global
                                   : vw__cell_rep_of(w, cell, ctx->wk->global) == replica);
        if (!hosted) misuse(ctx, "restored cell %d copy %d, which it does not host", cell, replica);
    }
    if (ctx->in_run) meter_note(ctx->wk, unit_busy(ctx->wk, cell, replica));
}

void vw_ctx_restore(vw_ctx *ctx, int cell, int replica)
{
    if (cell == ctx->cell && replica == ctx->rep) return;
    /* Back to a master this worker hosts, in a run without the stress switch (the home
       unit, or a cell a hand-off entered, which the walk left for a secondary ray). */
    if (!replica && (unsigned)cell < ctx->enter_cells && ctx->cells[cell].worker == ctx->global)
        meter_note(ctx->wk, &ctx->cells[cell].busy);
    else
        restore_slow(ctx, cell, replica);
    ctx->cell = cell;
    ctx->rep = replica;
}

void vw_send_cell(vw_ctx *ctx, int cell, int kind, const void *msg)
{
    vw_world *w = ctx->w;
    if (cell < 0 || cell >= w->ncells)
        misuse(ctx, "sent to cell %d, which does not exist (%d cells)", cell, w->ncells);
    if (kind >= 0 && kind < w->m->nkinds && !w->m->kinds[kind].handle)
        misuse(ctx, "sent message kind %d ('%s') to cell %d, but the kind has no handle (an "
               "output kind: sent with vw_send_output)", kind, w->m->kinds[kind].name, cell);
    int dest = w->cell_worker[cell];
    const vw__cell *c = &w->cells[cell];
    if (c->nreps && kind >= 0 && kind < w->m->nkinds &&
        (w->m->kinds[kind].flags & VW_MSG_INDEPENDENT)) {
        /* A duplicated cell: the master and its copies in turn, slot after slot of its
           share pattern. The receiving worker finds its copy by (cell, worker), so the
           header needs no copy number. */
        unsigned x = c->rr[(size_t)ctx->wk->local * VW__RR_STRIDE]++;
        int u = c->share_seq[x % (unsigned)c->share_len];
        if (u) dest = c->reps[u - 1].worker;
    }
    enqueue(ctx, dest, dest, cell, kind, msg);
}

int vw_send_point(vw_ctx *ctx, const double p[3], const double dir[3], int kind, const void *msg)
{
    int cell = vw_decomp_locate(ctx->w->decomp, p, dir);
    if (cell >= 0)
        vw_send_cell(ctx, cell, kind, msg);
    else
        check_msg(ctx, kind, msg);
    return cell;
}

int vw_send_face(vw_ctx *ctx, int face, int kind, const void *msg)
{
    /* A face that does not exist is a bug like an unknown cell: it used to send to no
       one and return 0, as a face on the world's wall does. */
    if (face < 0 || face > 5) misuse(ctx, "sent message kind %d to face %d (faces are 0..5)", kind, face);
    int nb[64];
    int n = vw_decomp_neighbours(ctx->w->decomp, ctx->cell, face, nb, 64);
    if (n == 0) check_msg(ctx, kind, msg);
    if (n > 64) {
        int *all = malloc(sizeof(int) * (size_t)n);
        if (!all) {
            vw__run_fail(ctx->w, VW_E_NOMEM, "cell %d: out of memory listing %d neighbours",
                         ctx->cell, n);
            return 0;
        }
        vw_decomp_neighbours(ctx->w->decomp, ctx->cell, face, all, n);
        for (int i = 0; i < n; i++) vw_send_cell(ctx, all[i], kind, msg);
        free(all);
        return n;
    }
    for (int i = 0; i < n; i++) vw_send_cell(ctx, nb[i], kind, msg);
    return n;
}

int vw_send_neighbours(vw_ctx *ctx, int kind, const void *msg)
{
    int n = 0;
    for (int f = 0; f < 6; f++) n += vw_send_face(ctx, f, kind, msg);
    return n;
}

void vw_send_output(vw_ctx *ctx, int kind, const void *msg)
{
    const vw_module *m = ctx->w->m;
    if (kind >= 0 && kind < m->nkinds && !m->kinds[kind].output)
        misuse(ctx, "sent message kind %d ('%s') to the output, but the kind has no output handler",
               kind, m->kinds[kind].name);
    enqueue(ctx, ctx->w->gworkers, VW__OUTPUT, -1, kind, msg);
}

/* The sized sends: the size of the record the module gives is checked against its kind's
   (which the plain sends copy, whatever the record's size), then the plain send does the
   rest, checks included. An unknown kind is left to the plain send to report. */
static inline void check_size(const vw_ctx *ctx, const char *call, int kind, size_t size)
{
    const vw_module *m = ctx->w->m;
    if (kind >= 0 && kind < m->nkinds && m->kinds[kind].size != size)
        misuse(ctx, "gave %s a record of %zu bytes for message kind %d ('%s'), whose size is %zu bytes",
               call, size, kind, m->kinds[kind].name, m->kinds[kind].size);
}

void vw_send_cell_sized(vw_ctx *ctx, int cell, int kind, const void *msg, size_t size)
{
    check_size(ctx, "vw_send_cell_sized", kind, size);
    vw_send_cell(ctx, cell, kind, msg);
}

int vw_send_point_sized(vw_ctx *ctx, const double p[3], const double dir[3], int kind,
                        const void *msg, size_t size)
{
    check_size(ctx, "vw_send_point_sized", kind, size);
    return vw_send_point(ctx, p, dir, kind, msg);
}

int vw_send_face_sized(vw_ctx *ctx, int face, int kind, const void *msg, size_t size)
{
    check_size(ctx, "vw_send_face_sized", kind, size);
    return vw_send_face(ctx, face, kind, msg);
}

int vw_send_neighbours_sized(vw_ctx *ctx, int kind, const void *msg, size_t size)
{
    check_size(ctx, "vw_send_neighbours_sized", kind, size);
    return vw_send_neighbours(ctx, kind, msg);
}

void vw_send_output_sized(vw_ctx *ctx, int kind, const void *msg, size_t size)
{
    check_size(ctx, "vw_send_output_sized", kind, size);
    vw_send_output(ctx, kind, msg);
}

void vw_ctx_fail(vw_ctx *ctx, vw_status status, const char *fmt, ...)
{
    if (!ctx->in_run)
        misuse(ctx, "called vw_ctx_fail from cell %d outside a run (cell_build returns its "
                    "status instead)", ctx->cell);
    char what[360];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt ? fmt : "failed", ap);
    va_end(ap);
    if (ctx->cell >= 0)
        vw__run_fail(ctx->w, status, "cell %d: %s", ctx->cell, what);
    else
        vw__run_fail(ctx->w, status, "%s", what);
}

void vw_count(vw_ctx *ctx, int idx, int64_t n)
{
    if ((unsigned)idx >= (unsigned)ctx->w->m->ncounters)
        misuse(ctx, "counted into counter %d of %d", idx, ctx->w->m->ncounters);
    if (ctx->cell >= 0) unit_counters(ctx->w, ctx->cell, ctx->rep)[idx] += n;
}

/* ---- the worker loop ---------------------------------------------------------------- */

static void handle_packet(vw__worker *wk, vw_ctx *ctx, vw__packet *p)
{
    vw_world *w = wk->w;
    size_t off = 0;
    int cur = -1, rep = 0;
    void *state = NULL;
    uint64_t *msgs_in = NULL;
    meter_start(wk, -1, 0);
    for (uint32_t i = 0; i < p->nmsgs; i++) {
        const vw__msg_header *h = (const vw__msg_header *)(p->data + off);
        if (h->cell != cur) {
            cur = h->cell;
            /* This worker's copy of the cell (the master, or a copy of a duplicated one). */
            rep = vw__cell_rep_of(w, cur, wk->global);
            if (rep < 0) {
                fprintf(stderr, "vwalls: worker %d received a message for cell %d, which it "
                        "does not host\n", wk->global, cur);
                abort();
            }
            meter_switch(wk, cur, rep);
            vw__cell *c = &w->cells[cur];
            state = *unit_state(w, cur, rep);
            msgs_in = rep ? &c->reps[rep - 1].messages_in : &c->messages_in;
        }
        (*msgs_in)++;
        ctx->cell = ctx->home_cell = h->cell;
        ctx->rep = ctx->home_rep = rep;
        const vw_msg_kind *k = &w->m->kinds[h->kind];
        /* A failed run drops the module's work; the message still counts as handled. */
        if (k->handle && !dropping(w)) k->handle(ctx, state, p->data + off + sizeof *h);
        /* A handler that handed off inline came back (vw_ctx_restore, which the meter
           notes): the next message of this cell needs no switch. */
        if (ctx->cell != ctx->home_cell || ctx->rep != ctx->home_rep)
            misuse(ctx, "returned from its handler of a kind %d message to cell %d in another "
                   "cell (vw_ctx_enter without vw_ctx_restore)", h->kind, h->cell);
        off += msg_stride(h->size);
    }
    meter_stop(wk);
    if (p->src >= 0 && vw__worker_process(w, p->src) == w->rank)
        atomic_fetch_sub(&w->workers[p->src - w->rank * w->nworkers].outstanding, vw__packet_charge(p));
}

/* Calls step() on the worker's cells round-robin; returns 1 if one of them worked,
   0 if none has step work, -1 if the worker is over its message cap: then step() is
   not called at all (the cells may still have work), and the worker must stay busy. */
static int run_step(vw__worker *wk, vw_ctx *ctx)
{
    vw_world *w = wk->w;
    if (!w->m->step || wk->ncells == 0 || dropping(w)) return 0;
    if (atomic_load(&wk->outstanding) > w->cfg.cap_bytes) return -1;
    for (int tries = 0; tries < wk->ncells; tries++) {
        int cell = wk->cells[wk->step_cursor], rep = wk->cell_rep[wk->step_cursor];
        wk->step_cursor = (wk->step_cursor + 1) % wk->ncells;
        ctx->cell = ctx->home_cell = cell;
        ctx->rep = ctx->home_rep = rep;
        meter_start(wk, cell, rep);
        int did = w->m->step(ctx, *unit_state(w, cell, rep));
        if (ctx->cell != cell || ctx->rep != rep)
            misuse(ctx, "returned from step() of cell %d in cell %d (vw_ctx_enter without "
                   "vw_ctx_restore)", cell, ctx->cell);
        meter_stop(wk);
        if (did) return 1;
    }
    return 0;
}

static vw__packet *take(vw__worker *wk)
{
    vw__packet *p = wk->head;
    if (p) {
        wk->head = p->next;
        if (!wk->head) wk->tail = NULL;
        p->next = NULL;
    }
    return p;
}

static void stress_pause(vw__worker *wk)
{
    if (!wk->w->cfg.stress_seed) return;
    uint64_t r = vw__rng_next(&wk->rng);
    if ((r & 7) == 0) {
        struct timespec ts = {0, (long)(r >> 40) % 200000};
        nanosleep(&ts, NULL);
    }
}

/* One run of a worker: until global quiescence. */
static void worker_run(vw__worker *wk)
{
    vw_world *w = wk->w;
    vw_ctx ctx = {.w = w, .wk = wk, .cell = -1, .home_cell = -1, .in_run = 1,
                  .enter_cells = w->cfg.stress_seed ? 0 : (unsigned)w->ncells,
                  .global = wk->global, .cells = w->cells, .handled = handled_kinds(w->m)};
    for (;;) {
        if (w->share_core) share_core(wk);
        pthread_mutex_lock(&wk->mu);
        vw__packet *p = take(wk);
        pthread_mutex_unlock(&wk->mu);
        if (p) {
            stress_pause(wk);
            handle_packet(wk, &ctx, p);
            free(p);
            vw__uncount(w);
            continue;
        }
        if (flush_all(wk)) continue;
        int stepped = run_step(wk, &ctx);
        if (stepped > 0) continue;
        /* A step() may send and still report no work (it handed over what it buffered):
           those packets leave now, or the worker went idle with them open and the run
           ended without them (they left at the next run, maybe to cells since moved). */
        if (stepped == 0 && flush_all(wk)) continue;
        if (stepped < 0) {
            /* Over the cap: what this worker sent is being handled by counted workers of
               this process, so the cap falls; wait for that (or a packet), still busy. */
            pthread_mutex_lock(&wk->mu);
            if (!wk->head) {
                struct timespec until;
                clock_gettime(CLOCK_REALTIME, &until);
                until.tv_nsec += 200000;
                if (until.tv_nsec >= 1000000000L) until.tv_sec++, until.tv_nsec -= 1000000000L;
                pthread_cond_timedwait(&wk->cv, &wk->mu, &until);
            }
            pthread_mutex_unlock(&wk->mu);
            continue;
        }
        /* Nothing to do: go idle until a packet arrives or the run ends. */
        pthread_mutex_lock(&wk->mu);
        if (wk->head) {
            pthread_mutex_unlock(&wk->mu);
            continue;
        }
        wk->busy = 0;
        pthread_mutex_unlock(&wk->mu);
        vw__uncount(w);
        pthread_mutex_lock(&wk->mu);
        while (!wk->head && !atomic_load(&w->finished)) pthread_cond_wait(&wk->cv, &wk->mu);
        if (!wk->head) {
            pthread_mutex_unlock(&wk->mu);
            break;
        }
        /* A counted packet is in the inbox, so active > 0 while we count ourselves. */
        wk->busy = 1;
        atomic_fetch_add(&w->active, 1);
        pthread_mutex_unlock(&wk->mu);
    }
}

/* A worker thread: one job (a run, or a build) per dispatch, until the pool stops. */
static void *worker_main(void *arg)
{
    vw__worker *wk = arg;
    vw_world *w = wk->w;
    unsigned gen = 0;
    pthread_mutex_lock(&w->pool_mu);
    for (;;) {
        while (w->run_gen == gen && !w->pool_quit) pthread_cond_wait(&w->pool_cv, &w->pool_mu);
        if (w->pool_quit) break;
        gen = w->run_gen;
        void (*job)(vw__worker *) = w->pool_job;
        pthread_mutex_unlock(&w->pool_mu);
        job(wk);
        pthread_mutex_lock(&w->pool_mu);
        if (--w->pool_left == 0) pthread_cond_broadcast(&w->pool_cv);
    }
    pthread_mutex_unlock(&w->pool_mu);
    return NULL;
}

void vw__runtime_stop(vw_world *w)
{
    if (!w->pool_started) return;
    pthread_mutex_lock(&w->pool_mu);
    w->pool_quit = 1;
    pthread_cond_broadcast(&w->pool_cv);
    pthread_mutex_unlock(&w->pool_mu);
    for (int i = 0; i < w->pool_started; i++) pthread_join(w->workers[i].thread, NULL);
    w->pool_started = 0;
    w->pool_quit = 0;
}

/* Starts the worker threads once; they wait for jobs. -1 when a thread cannot be
   started (those that were are stopped again). */
static int pool_start(vw_world *w)
{
    while (w->pool_started < w->nworkers) {
        vw__worker *wk = &w->workers[w->pool_started];
        if (pthread_create(&wk->thread, NULL, worker_main, wk) != 0) {
            int failed = w->pool_started;
            vw__runtime_stop(w);
            return failed;
        }
        w->pool_started++;
    }
    return -1;
}

/* Every worker does job once; everything the caller wrote before happens before. */
static void pool_dispatch(vw_world *w, void (*job)(vw__worker *))
{
    pthread_mutex_lock(&w->pool_mu);
    w->pool_job = job;
    w->pool_left = w->nworkers;
    w->run_gen++;
    pthread_cond_broadcast(&w->pool_cv);
    pthread_mutex_unlock(&w->pool_mu);
}

/* Until every worker has finished the job: its figures are then complete. */
static void pool_wait(vw_world *w)
{
    pthread_mutex_lock(&w->pool_mu);
    while (w->pool_left > 0) pthread_cond_wait(&w->pool_cv, &w->pool_mu);
    pthread_mutex_unlock(&w->pool_mu);
}

static vw_status runtime_run(vw_world *w);

vw_status vw__runtime_run(vw_world *w)
{
    const char *before = callbacks_begin(w, "a run (vw_world_run)");
    vw_status st = runtime_run(w);
    callbacks_end(w, before);
    return st;
}

static vw_status runtime_run(vw_world *w)
{
    /* The threads first: a run that cannot start them fails before it counts anything
       or takes the posted messages, so the next run starts as this one would have (a
       posted packet left counted in an inbox was handled uncounted by the next run,
       whose count then reached zero while a worker was busy: a cut-short run). */
    int failed = pool_start(w);
    if (failed >= 0) {
        vw_status st = vw__world_error(w, VW_E_LIMIT, "cannot start worker thread %d", failed);
        /* Other processes cannot finish without this one's workers; a process that
           cannot run them must end the job rather than leave the others waiting. */
        if (w->transport) {
            char msg[600];
            snprintf(msg, sizeof msg, "vwalls: rank %d: %s", w->rank, w->errmsg);
            vw_engine_abort(1, msg);
        }
        return st;
    }
    atomic_store(&w->finished, 0);
    atomic_store(&w->dropping, 0);
    atomic_store(&w->run_failed, 0);
    w->run_err = VW_OK;
    w->run_msg[0] = 0;
    /* With a transport, its thread (this one) is counted too: see the top of the file. */
    atomic_store(&w->active, w->nworkers + (w->transport ? 1 : 0));
    for (int i = 0; i < w->nworkers; i++) w->workers[i].busy = 1;
    /* Every run numbers the cells' batches afresh (vw_ctx_next_batch), and notes the
       cells every worker of this process holds a copy of, and those without copies
       (vw_ctx_enter). */
    for (int cl = 0; cl < w->ncells; cl++) {
        vw__cell *c = &w->cells[cl];
        atomic_store_explicit(&c->batches, 0, memory_order_relaxed);
        atomic_store_explicit(&c->spent, 0, memory_order_relaxed);
        c->stash.at = c->stash.end = 0;
        int local = vw__worker_process(w, c->worker) == w->rank;
        for (int r = 0; r < c->nreps; r++) {
            atomic_store_explicit(&c->reps[r].batches, 0, memory_order_relaxed);
            atomic_store_explicit(&c->reps[r].spent, 0, memory_order_relaxed);
            c->reps[r].stash.at = c->reps[r].stash.end = 0;
            local += vw__worker_process(w, c->reps[r].worker) == w->rank;
        }
        c->farmed = c->nreps > 0 && local == w->nworkers;
        c->solo = c->nreps ? -1 : c->worker;
    }
    /* Posted messages (every process holds them all): to the worker that hosts the
       cell now, if it is one of this process's; counted like any packet. */
    while (w->posted) {
        vw__packet *p = w->posted;
        w->posted = p->next;
        p->next = NULL;
        p->dest = w->cell_worker[((const vw__msg_header *)p->data)->cell];
        if (vw__worker_process(w, p->dest) == w->rank)
            vw__deliver(w, NULL, p);
        else
            free(p);
    }
    pool_dispatch(w, worker_run);
    vw_status st = VW_OK;
    if (w->transport) st = w->transport->run(w);
    pool_wait(w);
    w->runs++;
    vw__stats_local(w);
    if (w->transport && st == VW_OK) st = w->transport->sync(w);
    if (st != VW_OK) return st;
    /* A failed run fails on every process, with the message of the lowest failing one
       (vw_world_agree's "rank R: "); the pool's end ordered its workers' writes of
       run_err and run_msg before these reads. */
    st = atomic_load(&w->run_failed) ? w->run_err : VW_OK;
    char msg[512];
    snprintf(msg, sizeof msg, "%s", w->run_msg);
    /* (Still inside the run's callbacks window, which would refuse vw_world_agree.) */
    if (w->transport) st = vw__world_agree(w, st, msg, sizeof msg);
    if (st != VW_OK) return vw__world_error(w, st, "%s", msg);
    return VW_OK;
}

/* ---- building cells in parallel ----------------------------------------------------- */

static void build_job(vw__worker *wk)
{
    wk->build_status = VW_OK;
    for (int i = 0; i < wk->ncells && wk->build_status == VW_OK; i++) {
        vw__cell *c = &wk->w->cells[wk->cells[i]];
        int r = wk->cell_rep[i];
        if (r) {
            /* A copy rebuilds when the cell's objects changed since it was built. */
            vw__replica *rp = &c->reps[r - 1];
            if (rp->built && rp->built_version == c->version) continue;
            wk->build_status = vw__world_build_replica(wk->w, wk->cells[i], r, wk);
        } else {
            if (c->built && !c->dirty) continue;
            wk->build_status = vw__world_build_cell(wk->w, wk->cells[i], wk);
        }
        wk->build_cell = wk->cells[i];
        wk->build_rep = r;
    }
}

vw_status vw__runtime_build(vw_world *w, int *cell, int *rep)
{
    /* Each worker builds its own cells, on its own thread (or all here if threads
       cannot be started). */
    const char *before = callbacks_begin(w, "the cells' build (vw_world_commit)");
    if (pool_start(w) < 0) {
        pool_dispatch(w, build_job);
        pool_wait(w);
    } else {
        for (int i = 0; i < w->nworkers; i++) build_job(&w->workers[i]);
    }
    callbacks_end(w, before);
    /* Units are listed by cell, then copy (assign_units), so each worker's failure is
       its lowest failing unit, and the lowest of those is the lowest of all: the same
       unit is named whichever worker got there first. */
    const vw__worker *first = NULL;
    for (int i = 0; i < w->nworkers; i++) {
        const vw__worker *wk = &w->workers[i];
        if (wk->build_status == VW_OK) continue;
        if (!first || wk->build_cell < first->build_cell ||
            (wk->build_cell == first->build_cell && wk->build_rep < first->build_rep))
            first = wk;
    }
    if (!first) return VW_OK;
    *cell = first->build_cell;
    *rep = first->build_rep;
    return first->build_status;
}

/* Builds copy rep of a cell (0: the master) from the cell's objects, in the order they
   were added, on worker wk. */
static vw_status build_unit(vw_world *w, int cell, int rep, vw__worker *wk)
{
    vw__cell *c = &w->cells[cell];
    vw__replica *rp = rep ? &c->reps[rep - 1] : NULL;
    vw_ctx ctx = {.w = w, .wk = wk, .cell = cell, .rep = rep, .home_cell = cell, .home_rep = rep};
    size_t osz = w->m->object_size;
    const unsigned char *objs = NULL;
    unsigned char *gathered = NULL;
    if (c->nobjs) {
        /* A cell whose objects' records are a run of the world's, in order (a cell that
           holds them all), builds from the world's own records: they stay as they are
           while the cells are built, and a copy would be the largest allocation of the
           build. Under MPI the process keeps the records of the cells it builds (the
           commit fetched them: share_records, world.c). */
        const unsigned char *first = vw__world_record(w, c->objs[0]);
        size_t k = 1;
        while (first && k < c->nobjs && vw__world_record(w, c->objs[k]) == first + k * osz) k++;
        if (first && k == c->nobjs) {
            objs = first;
        } else {
            gathered = malloc(osz * c->nobjs);
            if (!gathered) return VW_E_NOMEM;
            for (size_t i = 0; i < c->nobjs; i++) {
                const unsigned char *r = vw__world_record(w, c->objs[i]);
                if (!r) { /* (not for want of memory: a defect, said as a state error) */
                    free(gathered);
                    return VW_E_STATE;
                }
                memcpy(gathered + i * osz, r, osz);
            }
            objs = gathered;
        }
    }
    int *built = rp ? &rp->built : &c->built;
    void **state = unit_state(w, cell, rep);
    if (*built && w->m->cell_free) w->m->cell_free(*state, w->user);
    *state = NULL;
    *built = 0;
    vw_status st = VW_OK;
    if (w->m->cell_build) st = w->m->cell_build(&ctx, objs, c->nobjs, state);
    free(gathered);
    if (st != VW_OK) {
        /* The build freed what it made (module.h): what it left here is not a state. */
        *state = NULL;
        return st;
    }
    *built = 1;
    if (rp)
        rp->built_version = c->version;
    else
        c->dirty = 0;
    return VW_OK;
}

/* The context handed to cell_build. */
vw_status vw__world_build_cell(vw_world *w, int cell, vw__worker *wk)
{
    return build_unit(w, cell, 0, wk);
}

vw_status vw__world_build_replica(vw_world *w, int cell, int rep, vw__worker *wk)
{
    return build_unit(w, cell, rep, wk);
}

/* The context of unit (cell, rep) of this process for a callback between runs: its
   worker's, outside any run. */
static vw_ctx between_runs(vw_world *w, int cell, int rep)
{
    int g = rep ? w->cells[cell].reps[rep - 1].worker : w->cells[cell].worker;
    return (vw_ctx){.w = w, .wk = &w->workers[g - w->rank * w->nworkers], .cell = cell,
                    .rep = rep, .home_cell = cell, .home_rep = rep};
}

/* The module's load estimate of unit (cell, rep), called between runs. */
static double unit_load(vw_world *w, int cell, int rep)
{
    vw_ctx ctx = between_runs(w, cell, rep);
    const char *before = callbacks_begin(w, "load()");
    double load = w->m->load(&ctx, *unit_state(w, cell, rep));
    callbacks_end(w, before);
    return load;
}

double vw__cell_load(vw_world *w, int cell) { return unit_load(w, cell, 0); }

double vw__replica_load(vw_world *w, int cell, int rep) { return unit_load(w, cell, rep); }

int vw__cell_done(vw_world *w, int cell)
{
    vw_ctx ctx = between_runs(w, cell, 0);
    const char *before = callbacks_begin(w, "done() (vw_world_done)");
    int done = w->m->done(&ctx, w->cells[cell].state);
    callbacks_end(w, before);
    return done;
}

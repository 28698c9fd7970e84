/* mpi.c - the MPI transport: packets between processes, funnelled through one
 * communication thread per process (the thread that called vw_world_run), and
 * termination detection across processes by waves of counts.
 *
 * Only the communication thread calls MPI (MPI_THREAD_FUNNELED suffices): workers hand
 * packets over through a locked queue, and received packets go into the workers'
 * inboxes through vw__deliver_local, counted in w->active like local ones.
 *
 * Termination (the four-counter method, Mattern 1987). Each process counts S, the
 * packets its workers handed to MPI, and R, the packets it received from MPI, this run.
 * A wave is one MPI_Iallreduce of (not idle, S, R) summed over processes, O(log P).
 * A process is idle when w->active == 1 (only the communication thread's own count
 * remains: no busy worker, no packet in any local inbox) and it holds no delayed
 * packet. It reads `active` before S and R, and only the communication thread can make
 * an idle process busy again (by delivering a received packet, which raises R first).
 * The run ends after two consecutive waves that both report every process idle and the
 * same totals with S == R. Why that is safe under any delay and order: a process's wave
 * k+1 contribution is made after every process's wave k contribution (it starts wave
 * k+1 only when wave k completed). Equal sums with monotone counters mean every
 * process's S and R stayed constant between its two contributions, so it received
 * nothing and stayed idle in between; at any instant between the last wave-k and the
 * first wave-(k+1) contribution, every process is idle and sent == received in total,
 * so no packet is in flight: nothing can ever happen again. Every process sees the
 * same wave results, so all decide at the same wave.
 */
#include "transport/mpi_internal.h"
#include "vwalls/engine.h"

#include <limits.h>
#include <sched.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* TAG_DATA: packets. TAG_TURN / TAG_TURN_BACK: a worker's request for a turn of a
   copy hosted by the receiver (vw_ctx_next_batch), and the answer. */
enum { TAG_DATA = 7301, TAG_TURN = 7302, TAG_TURN_BACK = 7303 };

/* A turn request: the waiting worker's, on its stack until `answered`. */
typedef struct turn_req {
    int cell, unit, thief, peer;
    uint64_t nbatches;
    uint64_t first, n; /* the answer: n turns from counter value first */
    int answered;      /* guarded by mu */
    struct turn_req *next;
} turn_req;

/* A control message's words on the wire: {id, cell, unit, thief, nbatches} for
   TAG_TURN, {id, first, n} for TAG_TURN_BACK. */
enum { TURN_WORDS = 5, BACK_WORDS = 3, CTL_MAX = 5 };
typedef struct ctl_msg {
    uint64_t v[CTL_MAX];
} ctl_msg;

/* Wire format: the packet record from `dest` to the end of its used data (dest, src,
   nmsgs, used, cap, data). Every process runs the same binary, so the layout matches;
   heterogeneous machines are not supported. */
#define WIRE_OFF offsetof(vw__packet, dest)
#define WIRE_HDR (offsetof(vw__packet, data) - WIRE_OFF)

/* A packet the stress switch holds back on the communication thread. */
typedef struct held {
    vw__packet *p;
    double until;
    int outgoing; /* 1: not yet sent to MPI; 0: received, not yet delivered */
} held;

typedef struct mpi_tp {
    vw__transport base;
    MPI_Comm comm;
    int level; /* thread level MPI gave */
    pthread_mutex_t mu;
    pthread_cond_t cv;
    vw__packet *qhead, *qtail; /* handed over by workers, not yet posted; guarded by mu */
    int sleeping;              /* the communication thread waits on cv; guarded by mu */
    turn_req *turn_q;          /* turn requests not yet sent; guarded by mu */
    pthread_cond_t turn_cv;    /* a turn request was answered; with mu */
    turn_req **asked;          /* sent turn requests by id (NULL: free), comm. thread */
    int nasked, capasked, waiting;
    MPI_Request *ctl_reqs;     /* control messages being sent, and their words */
    ctl_msg **ctl_bufs;
    int nctl, capctl;
    atomic_long sent;          /* S: packets handed to the transport this run */
    long received;             /* R: packets received this run (communication thread) */
    MPI_Request *reqs;         /* posted sends and their packets */
    vw__packet **sending;
    int nsend, capsend;
    int *done_idx;
    held *hold;
    int nhold, caphold;
    uint64_t rng;
    uint64_t waves; /* all runs: how many termination waves it took */
    int garble;     /* VW_FAULT=wire-garble: the next packet to a cell goes out garbled */
    int turn_garble; /* VW_FAULT=turn-garble: the next turn request names no copy */
} mpi_tp;

/* MPICH defines MPI_STATUSES_IGNORE as (MPI_Status *)1, which GCC 12's
   -Wstringop-overflow takes for a zero-sized array; passing it through a volatile
   read keeps the value and silences the false alarm. */
static MPI_Status *statuses_ignore(void)
{
    MPI_Status *volatile p = MPI_STATUSES_IGNORE;
    return p;
}

static mpi_tp *tp_of(vw_world *w) { return (mpi_tp *)w->transport; }

MPI_Comm vw__mpi_world_comm(const vw_world *w)
{
    return w->transport ? ((const mpi_tp *)w->transport)->comm : MPI_COMM_NULL;
}

int vw__mpi_first_differing(vw_world *w, uint64_t v)
{
    return vw__mpi_first_differing_n(w, &v, 1, NULL, NULL, NULL);
}

int vw__mpi_first_differing_n(vw_world *w, const uint64_t *v, int n, int *part, uint64_t *theirs,
                              uint64_t *first)
{
    MPI_Comm c = vw__mpi_world_comm(w);
    if (c == MPI_COMM_NULL || n < 1 || n > 256) return -1;
    uint64_t v0[256];
    memcpy(v0, v, sizeof *v0 * (size_t)n);
    MPI_Bcast(v0, n, MPI_UINT64_T, 0, c);
    int i = 0;
    while (i < n && v[i] == v0[i]) i++;
    /* rank * n + part: the lowest rank first, then its first part. */
    long long none = (long long)w->nprocs * n, mine = i < n ? (long long)w->rank * n + i : none, low = none;
    MPI_Allreduce(&mine, &low, 1, MPI_LONG_LONG, MPI_MIN, c);
    if (low == none) return -1;
    int r = (int)(low / n), k = (int)(low % n);
    uint64_t t = v[k];
    MPI_Bcast(&t, 1, MPI_UINT64_T, r, c);
    if (part) *part = k;
    if (theirs) *theirs = t;
    if (first) *first = v0[k];
    return r;
}

vw_status vw__mpi_fetch_records(vw_world *w, vw_status local, const uint64_t *ask,
                                size_t nask, unsigned char **got, char *msg, size_t len)
{
    *got = NULL;
    MPI_Comm c = vw__mpi_world_comm(w);
    int P = w->nprocs;
    size_t osz = w->m->object_size, n = w->nobjects;
    int *holder = NULL;
    uint64_t *req = NULL, *sorted = NULL;
    unsigned char *answer = NULL, *in = NULL, *mine = NULL;
    int *sn = calloc((size_t)P, sizeof *sn), *sat = calloc((size_t)P, sizeof *sat);
    int *rn = calloc((size_t)P, sizeof *rn), *rat = calloc((size_t)P, sizeof *rat);
    int *next = calloc((size_t)P, sizeof *next);
    vw_status st = local;
    if (st == VW_OK && !(sn && sat && rn && rat && next)) {
        st = VW_E_NOMEM;
        snprintf(msg, len, "out of memory fetching object records");
    }
    if (st == VW_OK && nask > INT_MAX) {
        st = VW_E_LIMIT;
        snprintf(msg, len, "fetching object records: %zu at a time (at most %d)", nask, INT_MAX);
    }
    /* Each agreement comes before a collective: a process that failed alone must not
       leave the others waiting in it. */
    if ((st = vw__mpi_agree(c, st, msg, len)) != VW_OK) goto done;
    unsigned long long mine_n = nask, total = 0;
    MPI_Allreduce(&mine_n, &total, 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, c);
    if (total == 0) goto done; /* (the same answer everywhere) */
    /* Which process sends each record: the lowest that keeps it. One int an object,
       reduced in pieces (MPI counts in int). */
    holder = malloc(sizeof *holder * (n ? n : 1));
    if (!holder) {
        st = VW_E_NOMEM;
        snprintf(msg, len, "out of memory fetching object records");
    }
    if ((st = vw__mpi_agree(c, st, msg, len)) != VW_OK) goto done;
    for (size_t id = 0; id < n; id++) holder[id] = vw__world_record(w, id) ? w->rank : P;
    for (size_t off = 0; off < n; off += (size_t)1 << 28) {
        size_t k = n - off < (size_t)1 << 28 ? n - off : (size_t)1 << 28;
        MPI_Allreduce(MPI_IN_PLACE, holder + off, (int)k, MPI_INT, MPI_MIN, c);
    }
    /* How many this process asks of each holder. */
    for (size_t i = 0; i < nask && st == VW_OK; i++) {
        int h = ask[i] < n ? holder[ask[i]] : P;
        if (h == P) {
            st = VW_E_STATE;
            snprintf(msg, len, "needs the record of object %llu, which no process keeps",
                     (unsigned long long)ask[i]);
        } else {
            sn[h]++;
        }
    }
    if ((st = vw__mpi_agree(c, st, msg, len)) != VW_OK) goto done;
    size_t nreq = 0;
    MPI_Alltoall(sn, 1, MPI_INT, rn, 1, MPI_INT, c);
    for (int p = 0; p < P; p++) {
        sat[p] = p ? sat[p - 1] + sn[p - 1] : 0;
        rat[p] = (int)nreq;
        nreq += (size_t)rn[p];
    }
    if (nreq > INT_MAX) {
        st = VW_E_LIMIT;
        snprintf(msg, len, "fetching object records: %zu asked of one process (at most %d)",
                 nreq, INT_MAX);
    }
    if (st == VW_OK) {
        req = malloc(sizeof *req * (nreq ? nreq : 1));
        sorted = malloc(sizeof *sorted * (nask ? nask : 1));
        answer = malloc(osz * (nreq ? nreq : 1));
        in = malloc(osz * (nask ? nask : 1));
        mine = malloc(osz * (nask ? nask : 1));
        if (!req || !sorted || !answer || !in || !mine) {
            st = VW_E_NOMEM;
            snprintf(msg, len, "out of memory fetching object records");
        }
    }
    if ((st = vw__mpi_agree(c, st, msg, len)) != VW_OK) goto done;
    /* The asks by holder, each holder's in ascending ids (as ask is). */
    for (size_t i = 0; i < nask; i++) {
        int h = holder[ask[i]];
        sorted[sat[h] + next[h]++] = ask[i];
    }
    MPI_Alltoallv(sorted, sn, sat, MPI_UINT64_T, req, rn, rat, MPI_UINT64_T, c);
    /* A holder keeps what it was asked for: it said so in the reduction. */
    for (size_t i = 0; i < nreq; i++) memcpy(answer + i * osz, vw__world_record(w, (size_t)req[i]), osz);
    MPI_Datatype rec;
    MPI_Type_contiguous((int)osz, MPI_BYTE, &rec);
    MPI_Type_commit(&rec);
    MPI_Alltoallv(answer, rn, rat, rec, in, sn, sat, rec, c);
    MPI_Type_free(&rec);
    /* Back into the order asked. */
    memset(next, 0, sizeof *next * (size_t)P);
    for (size_t i = 0; i < nask; i++) {
        int h = holder[ask[i]];
        memcpy(mine + osz * i, in + osz * (size_t)(sat[h] + next[h]++), osz);
    }
    *got = mine;
    mine = NULL;
done:
    free(mine);
    free(in);
    free(answer);
    free(sorted);
    free(req);
    free(holder);
    free(next);
    free(rat);
    free(rn);
    free(sat);
    free(sn);
    return st;
}

static void fatal(vw_world *w, const char *what)
{
    char msg[600];
    snprintf(msg, sizeof msg, "vwalls: rank %d: %s", w->rank, what);
    vw_engine_abort(1, msg);
}

static void *grow(void *p, int *cap, int need, size_t elem)
{
    if (need <= *cap) return p;
    int n = *cap ? *cap : 64;
    while (n < need) n *= 2;
    void *q = realloc(p, (size_t)n * elem);
    if (!q) {
        fprintf(stderr, "vwalls: out of memory in the MPI transport\n");
        abort();
    }
    *cap = n;
    return q;
}

/* ---- the workers' side --------------------------------------------------------------- */

/* Counted in S before the worker that sends can count itself idle, so a wave that sees
   that worker idle also sees this packet in S. */
static void tp_send(vw_world *w, vw__worker *from, vw__packet *p)
{
    mpi_tp *t = tp_of(w);
    if (from) atomic_fetch_add(&from->outstanding, vw__packet_charge(p));
    atomic_fetch_add(&t->sent, 1);
    pthread_mutex_lock(&t->mu);
    p->next = NULL;
    if (t->qtail)
        t->qtail->next = p;
    else
        t->qhead = p;
    t->qtail = p;
    if (t->sleeping) pthread_cond_signal(&t->cv);
    pthread_mutex_unlock(&t->mu);
}

/* Another process's copy's turn (vw__transport.take_turns): the request goes out through
   the communication thread, and the worker waits for the answer. The worker counts as
   busy meanwhile, so no termination wave can end the run before the answer is here, and
   control messages need no place in the packet counts S and R. */
static uint64_t tp_take_turns(vw_world *w, int cell, int unit, int thief, uint64_t nbatches,
                              uint64_t *first)
{
    mpi_tp *t = tp_of(w);
    const vw__cell *c = &w->cells[cell];
    turn_req r = {.cell = cell, .unit = unit, .thief = thief, .nbatches = nbatches};
    r.peer = vw__worker_process(w, unit ? c->reps[unit - 1].worker : c->worker);
    pthread_mutex_lock(&t->mu);
    r.next = t->turn_q;
    t->turn_q = &r;
    if (t->sleeping) pthread_cond_signal(&t->cv);
    while (!r.answered) pthread_cond_wait(&t->turn_cv, &t->mu);
    pthread_mutex_unlock(&t->mu);
    *first = r.first;
    return r.n;
}

/* ---- the communication thread ---------------------------------------------------------- */

/* Sends a control message of n words (a copy, freed when the send completes). */
static void ctl_send(vw_world *w, mpi_tp *t, int to, int tag, const uint64_t *v, int n)
{
    if (t->nctl == t->capctl) {
        int cap = t->capctl;
        t->ctl_reqs = grow(t->ctl_reqs, &cap, t->nctl + 1, sizeof *t->ctl_reqs);
        t->ctl_bufs = grow(t->ctl_bufs, &t->capctl, t->nctl + 1, sizeof *t->ctl_bufs);
    }
    ctl_msg *m = malloc(sizeof *m);
    if (!m) fatal(w, "out of memory sending a turn request");
    memcpy(m->v, v, (size_t)n * sizeof *v);
    t->ctl_bufs[t->nctl] = m;
    MPI_Isend(m->v, n, MPI_UINT64_T, to, tag, t->comm, &t->ctl_reqs[t->nctl]);
    t->nctl++;
}

static void ctl_complete(mpi_tp *t)
{
    int k = 0;
    for (int i = 0; i < t->nctl; i++) {
        int done = 0;
        MPI_Test(&t->ctl_reqs[i], &done, MPI_STATUS_IGNORE);
        if (done) {
            free(t->ctl_bufs[i]);
            continue;
        }
        t->ctl_reqs[k] = t->ctl_reqs[i];
        t->ctl_bufs[k++] = t->ctl_bufs[i];
    }
    t->nctl = k;
}

/* Sends the workers' turn requests, each under a free id of `asked`. */
static int post_turns(vw_world *w, mpi_tp *t)
{
    pthread_mutex_lock(&t->mu);
    turn_req *r = t->turn_q;
    t->turn_q = NULL;
    pthread_mutex_unlock(&t->mu);
    int any = r != NULL;
    for (; r; r = r->next) {
        int id = 0;
        while (id < t->nasked && t->asked[id]) id++;
        if (id == t->nasked) {
            t->asked = grow(t->asked, &t->capasked, t->nasked + 1, sizeof *t->asked);
            t->nasked++;
        }
        t->asked[id] = r;
        t->waiting++;
        uint64_t v[TURN_WORDS] = {(uint64_t)id, (uint64_t)r->cell, (uint64_t)r->unit,
                                  (uint64_t)r->thief, r->nbatches};
        if (t->turn_garble) { /* the check's test: a copy one past the cell's last */
            v[2] = (uint64_t)w->cells[r->cell].nreps + 1;
            t->turn_garble = 0;
        }
        ctl_send(w, t, r->peer, TAG_TURN, v, TURN_WORDS);
    }
    return any;
}

/* A turn message that MPI_Iprobe found (s): another process's request, answered at
   once, or the answer to one of ours, handed to its waiting worker. */
static void receive_turn(vw_world *w, mpi_tp *t, const MPI_Status *s)
{
    int n = 0;
    MPI_Get_count(s, MPI_UINT64_T, &n);
    char what[300];
    int is_turn = s->MPI_TAG == TAG_TURN;
    if (n != (is_turn ? TURN_WORDS : BACK_WORDS)) {
        snprintf(what, sizeof what, "a turn %s from rank %d has %d words "
                 "(do all processes run the same binary?)", is_turn ? "request" : "answer",
                 s->MPI_SOURCE, n);
        fatal(w, what);
    }
    uint64_t v[CTL_MAX];
    MPI_Recv(v, n, MPI_UINT64_T, s->MPI_SOURCE, s->MPI_TAG, t->comm, MPI_STATUS_IGNORE);
    if (is_turn) {
        uint64_t first = 0;
        uint64_t got = v[1] < (uint64_t)INT_MAX && v[2] < (uint64_t)INT_MAX &&
                               v[3] < (uint64_t)INT_MAX
                           ? vw__take_turns(w, (int)v[1], (int)v[2], (int)v[3], v[4], &first)
                           : UINT64_MAX;
        if (got == UINT64_MAX) {
            snprintf(what, sizeof what, "rank %d asked for turns of cell %llu, copy %llu, "
                     "which this process does not host", s->MPI_SOURCE,
                     (unsigned long long)v[1], (unsigned long long)v[2]);
            fatal(w, what);
        }
        uint64_t back[BACK_WORDS] = {v[0], first, got};
        ctl_send(w, t, s->MPI_SOURCE, TAG_TURN_BACK, back, BACK_WORDS);
        return;
    }
    turn_req *r = v[0] < (uint64_t)t->nasked ? t->asked[v[0]] : NULL;
    if (!r || r->peer != s->MPI_SOURCE || v[2] > UINT64_MAX - v[1]) {
        snprintf(what, sizeof what, "rank %d answered turn request %llu, which was not "
                 "asked of it, or with a wrong range", s->MPI_SOURCE, (unsigned long long)v[0]);
        fatal(w, what);
    }
    t->asked[v[0]] = NULL;
    t->waiting--;
    pthread_mutex_lock(&t->mu);
    r->first = v[1];
    r->n = v[2];
    r->answered = 1;
    pthread_cond_broadcast(&t->turn_cv);
    pthread_mutex_unlock(&t->mu);
}

static void post_send(vw_world *w, mpi_tp *t, vw__packet *p)
{
    int to = p->dest == VW__OUTPUT ? 0 : vw__worker_process(w, p->dest);
    if (t->nsend == t->capsend) {
        /* reqs, sending and done_idx always have capsend entries. */
        int cap = t->capsend;
        t->reqs = grow(t->reqs, &cap, t->nsend + 1, sizeof *t->reqs);
        cap = t->capsend;
        t->done_idx = grow(t->done_idx, &cap, t->nsend + 1, sizeof *t->done_idx);
        t->sending = grow(t->sending, &t->capsend, t->nsend + 1, sizeof *t->sending);
    }
    if (t->garble && p->dest != VW__OUTPUT && p->nmsgs) {
        /* The wire check's test: the first message's kind one past the module's last. */
        vw__msg_header *h = (vw__msg_header *)p->data;
        h->kind = (uint16_t)w->m->nkinds;
        t->garble = 0;
    }
    t->sending[t->nsend] = p;
    MPI_Isend((char *)p + WIRE_OFF, (int)(WIRE_HDR + p->used), MPI_BYTE, to, TAG_DATA, t->comm,
              &t->reqs[t->nsend]);
    t->nsend++;
}

static void hold_packet(vw_world *w, mpi_tp *t, vw__packet *p, int outgoing)
{
    (void)w;
    t->hold = grow(t->hold, &t->caphold, t->nhold + 1, sizeof *t->hold);
    uint64_t r = vw__rng_next(&t->rng);
    t->hold[t->nhold++] = (held){p, vw__now() + 1e-6 * (double)(r % 2000), outgoing};
}

static int stress_roll(vw_world *w, mpi_tp *t) { return w->cfg.stress_seed && (vw__rng_next(&t->rng) & 3) == 0; }

/* Posts the packets the workers handed over (the stress switch holds some back). */
static int post_sends(vw_world *w, mpi_tp *t)
{
    pthread_mutex_lock(&t->mu);
    vw__packet *p = t->qhead;
    t->qhead = t->qtail = NULL;
    pthread_mutex_unlock(&t->mu);
    int any = p != NULL;
    while (p) {
        vw__packet *next = p->next;
        p->next = NULL;
        if (stress_roll(w, t))
            hold_packet(w, t, p, 1);
        else
            post_send(w, t, p);
        p = next;
    }
    return any;
}

/* Frees the packets whose sends completed and gives their bytes back to the sender's
   memory cap. */
static int complete_sends(vw_world *w, mpi_tp *t)
{
    if (!t->nsend) return 0;
    int ndone = 0;
    MPI_Testsome(t->nsend, t->reqs, &ndone, t->done_idx, statuses_ignore());
    if (ndone == MPI_UNDEFINED || ndone == 0) return 0;
    for (int i = 0; i < ndone; i++) {
        vw__packet *p = t->sending[t->done_idx[i]];
        if (p->src >= 0 && vw__worker_process(w, p->src) == w->rank)
            atomic_fetch_sub(&w->workers[p->src - w->rank * w->nworkers].outstanding, vw__packet_charge(p));
        free(p);
        t->sending[t->done_idx[i]] = NULL;
    }
    int k = 0;
    for (int i = 0; i < t->nsend; i++)
        if (t->sending[i]) {
            t->sending[k] = t->sending[i];
            t->reqs[k] = t->reqs[i];
            k++;
        }
    t->nsend = k;
    return 1;
}

static void deliver_received(vw_world *w, mpi_tp *t, vw__packet *p)
{
    if (p->dest == VW__OUTPUT) {
        vw__run_output(w, p); /* output creates no work: nothing to count */
        free(p);
        return;
    }
    vw__deliver_local(w, p, w->cfg.stress_seed ? &t->rng : NULL);
}

/* Receives what has arrived (at most a batch, so sends and waves keep moving): packets,
   and turn requests and answers. */
static int receive(vw_world *w, mpi_tp *t)
{
    int any = 0;
    for (int k = 0; k < 64; k++) {
        int flag = 0, n = 0;
        MPI_Status s;
        MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, t->comm, &flag, &s);
        if (!flag) break;
        any = 1;
        if (s.MPI_TAG == TAG_TURN || s.MPI_TAG == TAG_TURN_BACK) {
            receive_turn(w, t, &s);
            continue;
        }
        if (s.MPI_TAG != TAG_DATA) {
            char what[120];
            snprintf(what, sizeof what, "received a message with tag %d from rank %d",
                     s.MPI_TAG, s.MPI_SOURCE);
            fatal(w, what);
        }
        MPI_Get_count(&s, MPI_BYTE, &n);
        if (n < (int)WIRE_HDR) fatal(w, "received a truncated packet");
        size_t cap = (size_t)n - WIRE_HDR;
        vw__packet *p = vw__packet_new(0, 0, cap);
        /* MPI has no way to take a message without the room for it: the job ends. */
        if (!p) fatal(w, "out of memory receiving a packet");
        MPI_Recv((char *)p + WIRE_OFF, n, MPI_BYTE, s.MPI_SOURCE, TAG_DATA, t->comm, MPI_STATUS_IGNORE);
        p->next = NULL;
        p->cap = cap;
        int dest_ok = p->dest == VW__OUTPUT ? w->rank == 0
                                            : p->dest >= 0 && p->dest < w->gworkers &&
                                                  vw__worker_process(w, p->dest) == w->rank;
        char why[160];
        const char *problem = p->used != cap || !dest_ok ? "its header is wrong"
                                                          : vw__packet_problem(w, p, why, sizeof why);
        if (problem) {
            char what[400];
            snprintf(what, sizeof what, "packet from rank %d for worker %d is malformed: %s "
                     "(do all processes run the same binary and world?)", s.MPI_SOURCE, p->dest,
                     problem);
            fatal(w, what);
        }
        t->received++;
        if (stress_roll(w, t))
            hold_packet(w, t, p, 0);
        else
            deliver_received(w, t, p);
    }
    return any;
}

/* Stress: lets held packets go once their time has come, in random order. */
static int release_held(vw_world *w, mpi_tp *t)
{
    if (!t->nhold) return 0;
    double now = vw__now();
    int any = 0;
    for (int i = 0; i < t->nhold;) {
        uint64_t r = vw__rng_next(&t->rng);
        int j = i + (int)(r % (uint64_t)(t->nhold - i));
        held h = t->hold[j];
        if (h.until > now) {
            i++;
            continue;
        }
        t->hold[j] = t->hold[--t->nhold];
        if (h.outgoing)
            post_send(w, t, h.p);
        else
            deliver_received(w, t, h.p);
        any = 1;
    }
    return any;
}

/* Waits a little when nothing happened: a worker handing over a packet wakes us at
   once; arrivals from MPI are seen after at most the current pause. */
static void pause_idle(mpi_tp *t, int rounds)
{
    if (rounds < 32) {
        sched_yield();
        return;
    }
    long us = rounds < 64 ? 20 : rounds < 256 ? 100 : 400;
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    ts.tv_nsec += us * 1000;
    if (ts.tv_nsec >= 1000000000L) {
        ts.tv_sec++;
        ts.tv_nsec -= 1000000000L;
    }
    pthread_mutex_lock(&t->mu);
    if (!t->qhead && !t->turn_q) {
        t->sleeping = 1;
        pthread_cond_timedwait(&t->cv, &t->mu, &ts);
        t->sleeping = 0;
    }
    pthread_mutex_unlock(&t->mu);
}

static vw_status tp_run(vw_world *w)
{
    mpi_tp *t = tp_of(w);
    int is_main = 0;
    MPI_Is_thread_main(&is_main);
    if (!is_main && t->level < MPI_THREAD_SERIALIZED)
        fatal(w, "vw_world_run called from a thread other than the one that initialised MPI, "
                 "which MPI_THREAD_FUNNELED forbids");
    /* A wave sums (not idle, S, R, dropping): the last tells every process that one of
       them failed its run, so all stop the module's work (vw_world.dropping). */
    int64_t in[4], out[4], prev[3] = {1, -1, -1};
    MPI_Request wave = MPI_REQUEST_NULL;
    double wave_start = 0;
    int rounds = 0;
    for (;;) {
        int progress = post_sends(w, t);
        progress |= complete_sends(w, t);
        progress |= receive(w, t);
        progress |= release_held(w, t);
        progress |= post_turns(w, t);
        ctl_complete(t);
        if (w->cfg.stress_seed && (vw__rng_next(&t->rng) & 15) == 0) {
            struct timespec ts = {0, (long)(vw__rng_next(&t->rng) % 300000)};
            nanosleep(&ts, NULL);
        }
        if (wave != MPI_REQUEST_NULL) {
            int done = 0;
            MPI_Test(&wave, &done, MPI_STATUS_IGNORE);
            if (done) {
                t->waves++;
                if (out[3] && !atomic_load(&w->dropping)) atomic_store(&w->dropping, 1);
                if (out[0] == 0 && out[1] == out[2] && prev[0] == 0 && prev[1] == out[1] &&
                    prev[2] == out[2])
                    break;
                memcpy(prev, out, sizeof prev);
                progress = 1;
            }
        }
        if (wave == MPI_REQUEST_NULL) {
            /* Read `active` first: see the top of the file. */
            int idle = atomic_load(&w->active) == 1 && t->nhold == 0;
            double now = vw__now();
            /* Busy processes join a wave at most every 2 ms, so waves cost nothing
               while there is work; idle ones start the next one at once. */
            if (idle || now - wave_start > 0.002) {
                in[0] = !idle;
                in[1] = (int64_t)atomic_load(&t->sent);
                in[2] = (int64_t)t->received;
                in[3] = atomic_load(&w->dropping);
                MPI_Iallreduce(in, out, 4, MPI_INT64_T, MPI_SUM, t->comm, &wave);
                wave_start = now;
            }
        }
        if (progress)
            rounds = 0;
        else
            pause_idle(t, rounds++);
    }
    /* S == R: every posted send has been received, so its request completes. */
    if (t->nsend) MPI_Waitall(t->nsend, t->reqs, statuses_ignore());
    for (int i = 0; i < t->nsend; i++) {
        vw__packet *p = t->sending[i];
        if (p->src >= 0 && vw__worker_process(w, p->src) == w->rank)
            atomic_fetch_sub(&w->workers[p->src - w->rank * w->nworkers].outstanding, vw__packet_charge(p));
        free(p);
    }
    t->nsend = 0;
    /* Every request was answered before its worker went idle, so every control message
       was received. */
    if (t->waiting) fatal(w, "a run ended with a turn request unanswered");
    if (t->nctl) MPI_Waitall(t->nctl, t->ctl_reqs, statuses_ignore());
    for (int i = 0; i < t->nctl; i++) free(t->ctl_bufs[i]);
    t->nctl = 0;
    atomic_store(&t->sent, 0);
    t->received = 0;
    vw__uncount(w); /* our count: this brings active to 0 and ends the workers' loops */
    return VW_OK;
}

/* ---- after a run: every process gets the whole job's figures -------------------------- */

/* A cell's figures are written only by its host, the others hold zeros or a copy from
   the last sync, so a sum where only the host contributes gives the host's figures.
   The copies of duplicated cells follow the cells, as rows of their own (every process
   knows the same copies, so the layout agrees), each contributed by its own host. */
/* The integers of a worker's figures (vw__worker_stats) in the sync. */
#define SYNC_WORKER_WORDS 9

static vw_status tp_sync(vw_world *w)
{
    mpi_tp *t = tp_of(w);
    int nc = w->m->ncounters;
    size_t nu = (size_t)w->ncells + (size_t)vw__replica_total(w); /* cells, then copies */
    size_t ni = nu * (size_t)(1 + nc), nd = nu * 2;
    size_t nw = (size_t)w->gworkers;
    int64_t *iv = calloc(ni + SYNC_WORKER_WORDS * nw, sizeof *iv);
    double *dv = calloc(nd + nw, sizeof *dv);
    if (!iv || !dv) {
        free(iv);
        free(dv);
        fatal(w, "out of memory gathering the run's figures");
    }
    for (int c = 0; c < w->ncells; c++) {
        vw__cell *cl = &w->cells[c];
        if (vw__worker_process(w, cl->worker) != w->rank) continue;
        int64_t *row = iv + (size_t)c * (size_t)(1 + nc);
        row[0] = (int64_t)cl->messages_in;
        for (int k = 0; k < nc; k++) row[1 + k] = cl->counters[k];
        dv[2 * c] = cl->busy.s;
        dv[2 * c + 1] = w->m->load && cl->built ? vw__cell_load(w, c) : cl->busy.s;
    }
    size_t u = (size_t)w->ncells;
    for (int c = 0; c < w->ncells; c++)
        for (int r = 0; r < w->cells[c].nreps; r++, u++) {
            vw__replica *rp = &w->cells[c].reps[r];
            if (vw__worker_process(w, rp->worker) != w->rank) continue;
            int64_t *row = iv + u * (size_t)(1 + nc);
            row[0] = (int64_t)rp->messages_in;
            for (int k = 0; k < nc; k++) row[1 + k] = rp->counters[k];
            dv[2 * u] = rp->busy.s;
            dv[2 * u + 1] = w->m->load && rp->built ? vw__replica_load(w, c, r + 1) : rp->busy.s;
        }
    int64_t *wv = iv + ni;
    for (int i = 0; i < w->nworkers; i++) {
        const vw__worker_stats *s = &w->wstats[w->workers[i].global];
        int64_t *row = wv + SYNC_WORKER_WORDS * (size_t)w->workers[i].global;
        row[0] = (int64_t)s->msgs_sent;
        row[1] = (int64_t)s->bytes_sent;
        row[2] = (int64_t)s->packets_sent;
        row[3] = (int64_t)s->msgs_remote;
        row[4] = (int64_t)s->bytes_remote;
        row[5] = (int64_t)s->peak_rss;
        row[6] = (int64_t)s->turns_remote;
        row[7] = (int64_t)s->records;
        row[8] = (int64_t)s->fetched;
        dv[nd + (size_t)w->workers[i].global] = s->busy_s;
    }
    MPI_Allreduce(MPI_IN_PLACE, iv, (int)(ni + SYNC_WORKER_WORDS * nw), MPI_INT64_T, MPI_SUM, t->comm);
    MPI_Allreduce(MPI_IN_PLACE, dv, (int)(nd + nw), MPI_DOUBLE, MPI_SUM, t->comm);
    for (int c = 0; c < w->ncells; c++) {
        vw__cell *cl = &w->cells[c];
        const int64_t *row = iv + (size_t)c * (size_t)(1 + nc);
        cl->messages_in = (uint64_t)row[0];
        for (int k = 0; k < nc; k++) cl->counters[k] = row[1 + k];
        cl->busy.s = dv[2 * c];
        cl->load = dv[2 * c + 1];
    }
    u = (size_t)w->ncells;
    for (int c = 0; c < w->ncells; c++)
        for (int r = 0; r < w->cells[c].nreps; r++, u++) {
            vw__replica *rp = &w->cells[c].reps[r];
            const int64_t *row = iv + u * (size_t)(1 + nc);
            rp->messages_in = (uint64_t)row[0];
            for (int k = 0; k < nc; k++) rp->counters[k] = row[1 + k];
            rp->busy.s = dv[2 * u];
            rp->load = dv[2 * u + 1];
        }
    for (size_t g = 0; g < nw; g++) {
        vw__worker_stats *s = &w->wstats[g];
        const int64_t *row = wv + SYNC_WORKER_WORDS * g;
        s->msgs_sent = (uint64_t)row[0];
        s->bytes_sent = (uint64_t)row[1];
        s->packets_sent = (uint64_t)row[2];
        s->msgs_remote = (uint64_t)row[3];
        s->bytes_remote = (uint64_t)row[4];
        s->peak_rss = (uint64_t)row[5];
        s->turns_remote = (uint64_t)row[6];
        s->records = (uint64_t)row[7];
        s->fetched = (uint64_t)row[8];
        s->busy_s = dv[nd + g];
    }
    free(iv);
    free(dv);
    return VW_OK;
}

static void tp_free(vw_world *w)
{
    mpi_tp *t = tp_of(w);
    int fin = 0;
    MPI_Finalized(&fin);
    if (!fin && t->comm != MPI_COMM_NULL) MPI_Comm_free(&t->comm);
    while (t->qhead) {
        vw__packet *p = t->qhead;
        t->qhead = p->next;
        free(p);
    }
    for (int i = 0; i < t->nhold; i++) free(t->hold[i].p);
    free(t->hold);
    free(t->reqs);
    free(t->sending);
    free(t->done_idx);
    free(t->asked);
    free(t->ctl_reqs);
    free(t->ctl_bufs);
    pthread_mutex_destroy(&t->mu);
    pthread_cond_destroy(&t->cv);
    pthread_cond_destroy(&t->turn_cv);
    free(t);
    w->transport = NULL;
}

/* ---- choosing the engine at create ------------------------------------------------------ */

vw_status vw__mpi_attach(vw_world *w)
{
    char msg[300] = "";
    int init = 0, fin = 0;
    MPI_Initialized(&init);
    MPI_Finalized(&fin);
    MPI_Comm base;
    if (w->cfg.mpi_comm) {
        if (!init || fin)
            return vw__world_error(w, VW_E_STATE, "an MPI communicator was given but MPI is not initialised");
        base = *(const MPI_Comm *)w->cfg.mpi_comm;
    } else if (init && !fin) {
        base = MPI_COMM_WORLD;
    } else if (!fin && vw__mpi_launcher_env()) {
        vw_status st = vw__mpi_autoinit(msg, sizeof msg);
        if (st != VW_OK) return vw__world_error(w, st, "%s", msg);
        base = MPI_COMM_WORLD;
    } else {
        return VW_OK; /* the threads engine alone */
    }
    int level = MPI_THREAD_SINGLE, size = 1, rank = 0;
    MPI_Query_thread(&level);
    MPI_Comm_size(base, &size);
    MPI_Comm_rank(base, &rank);
    if (level < VW__MPI_THREAD_LEVEL)
        return vw__world_error(w, VW_E_MPI, "MPI was initialised with thread level %d; vwalls needs "
                               "at least MPI_THREAD_FUNNELED", level);
    if (size == 1) return VW_OK; /* one process: the threads engine, without polling */
    /* By default (workers = 0) a process runs its share of its host's cores: several
       processes on one host that may all run on every core would otherwise each start a
       worker per core (Open MPI binds more than two processes to a socket, or none at
       all when oversubscribed), k times the cores in all. Collective, so before the
       allocation below can fail. */
    if (w->cfg.workers <= 0) w->nworkers = vw__mpi_core_share(base, w->nworkers);
    /* Every process needs the same worker count (global worker = rank * W + local). With
       workers = 0 (as many as cores) the machines may differ: take the smallest. The same
       reduction finds the lowest process that could not allocate the transport: all
       processes go on to MPI_Comm_dup (collective), or none does. */
    mpi_tp *t = calloc(1, sizeof *t);
    int wmin, wmax, mine[3] = {w->nworkers, -w->nworkers, t ? size : rank}, all[3];
    MPI_Allreduce(mine, all, 3, MPI_INT, MPI_MIN, base);
    wmin = all[0];
    wmax = -all[1];
    if (all[2] < size) {
        free(t);
        return vw__world_error(w, VW_E_NOMEM, "rank %d: out of memory creating the MPI transport",
                               all[2]);
    }
    if (wmin != wmax && w->cfg.workers > 0) {
        free(t);
        return vw__world_error(w, VW_E_INVAL, "processes were given different worker counts (%d to %d)",
                               wmin, wmax);
    }
    MPI_Comm_dup(base, &t->comm);
    MPI_Comm_set_errhandler(t->comm, MPI_ERRORS_ARE_FATAL);
    t->level = level;
    pthread_mutex_init(&t->mu, NULL);
    pthread_cond_init(&t->cv, NULL);
    pthread_cond_init(&t->turn_cv, NULL);
    atomic_init(&t->sent, 0);
    t->rng = w->cfg.stress_seed * 0x9e3779b97f4a7c15ull + (uint64_t)rank * 7919u + 3;
    t->garble = vw_test_fault("wire-garble");
    t->turn_garble = vw_test_fault("turn-garble");
    t->base.name = "mpi";
    t->base.send = tp_send;
    t->base.run = tp_run;
    t->base.sync = tp_sync;
    t->base.take_turns = tp_take_turns;
    t->base.free = tp_free;
    t->base.impl = t;
    w->transport = &t->base;
    w->rank = rank;
    w->nprocs = size;
    w->nworkers = wmin;
    return VW_OK;
}

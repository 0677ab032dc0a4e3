/*
 * QEMU TCG plugin "stopwatch": counts the guest instructions executed between two
 * marker functions of the firmware, exactly (no sampling, no timer).
 *
 * Arguments: start=ADDR,stop=ADDR,out=FILE. Every time the guest reaches the first
 * instruction of the start marker the plugin notes its running instruction count;
 * when it reaches the stop marker it appends the difference to FILE, one decimal
 * number per line. Thumb addresses are given without their low bit.
 *
 * Optional profile=N,pcs=FILE (`cargo xtask bench --profile`): during the N-th region
 * (0 = the first, the empty one) every executed instruction's address is counted, and
 * at exit FILE gets one "ADDR COUNT" line (hex, decimal) per address executed there.
 * Still exact: every instruction, no sampling.
 *
 * Built by `cargo xtask bench` with gcc. Debian ships no qemu-plugin.h, so the few
 * declarations of the plugin API (version 1, QEMU 6.x-8.x) it uses are repeated here.
 */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef uint64_t qemu_plugin_id_t;
struct qemu_plugin_tb;
struct qemu_plugin_insn;
struct qemu_info_t;

enum qemu_plugin_cb_flags {
    QEMU_PLUGIN_CB_NO_REGS,
    QEMU_PLUGIN_CB_R_REGS,
    QEMU_PLUGIN_CB_RW_REGS,
};

enum qemu_plugin_op {
    QEMU_PLUGIN_INLINE_ADD_U64,
};

typedef void (*qemu_plugin_vcpu_tb_trans_cb_t)(qemu_plugin_id_t id, struct qemu_plugin_tb *tb);
typedef void (*qemu_plugin_vcpu_udata_cb_t)(unsigned int vcpu_index, void *userdata);
typedef void (*qemu_plugin_udata_cb_t)(qemu_plugin_id_t id, void *userdata);

extern void qemu_plugin_register_vcpu_tb_trans_cb(qemu_plugin_id_t id,
                                                  qemu_plugin_vcpu_tb_trans_cb_t cb);
extern size_t qemu_plugin_tb_n_insns(const struct qemu_plugin_tb *tb);
extern struct qemu_plugin_insn *qemu_plugin_tb_get_insn(const struct qemu_plugin_tb *tb,
                                                        size_t idx);
extern uint64_t qemu_plugin_insn_vaddr(const struct qemu_plugin_insn *insn);
extern void qemu_plugin_register_vcpu_insn_exec_cb(struct qemu_plugin_insn *insn,
                                                   qemu_plugin_vcpu_udata_cb_t cb,
                                                   enum qemu_plugin_cb_flags flags,
                                                   void *userdata);
extern void qemu_plugin_register_vcpu_insn_exec_inline(struct qemu_plugin_insn *insn,
                                                       enum qemu_plugin_op op, void *ptr,
                                                       uint64_t imm);
extern void qemu_plugin_register_atexit_cb(qemu_plugin_id_t id, qemu_plugin_udata_cb_t cb,
                                           void *userdata);

__attribute__((visibility("default"))) int qemu_plugin_version = 1;

static uint64_t executed;   /* guest instructions so far (one vCPU) */
static uint64_t started_at;
static bool running;
static uint64_t start_addr, stop_addr;
static FILE *out;

/* The profile: one counter per halfword of the code window [base, base + PROFILE_SPAN),
 * base = the start marker's address rounded down to PROFILE_SPAN (flash at 0 on the
 * MPS2, at 0x08000000 on the STM32). */
#define PROFILE_SPAN (4u << 20)
static bool profiling;
static uint64_t profile_base;
static uint64_t profile_region, regions_started;
static uint64_t *pc_counts;
static FILE *pcs_out;

static void on_start(unsigned int vcpu, void *userdata)
{
    (void)vcpu;
    (void)userdata;
    started_at = executed;
    running = true;
    regions_started++;
}

static void on_insn(unsigned int vcpu, void *userdata)
{
    (void)vcpu;
    if (running && regions_started == profile_region + 1) {
        pc_counts[((uintptr_t)userdata - profile_base) >> 1]++;
    }
}

static void on_stop(unsigned int vcpu, void *userdata)
{
    (void)vcpu;
    (void)userdata;
    if (running) {
        fprintf(out, "%llu\n", (unsigned long long)(executed - started_at));
    } else {
        fprintf(out, "unpaired stop\n");
    }
    fflush(out);
    running = false;
}

static void on_translate(qemu_plugin_id_t id, struct qemu_plugin_tb *tb)
{
    (void)id;
    size_t n = qemu_plugin_tb_n_insns(tb);
    for (size_t i = 0; i < n; i++) {
        struct qemu_plugin_insn *insn = qemu_plugin_tb_get_insn(tb, i);
        uint64_t pc = qemu_plugin_insn_vaddr(insn);
        qemu_plugin_register_vcpu_insn_exec_inline(insn, QEMU_PLUGIN_INLINE_ADD_U64, &executed, 1);
        if (profiling && pc >= profile_base && pc - profile_base < PROFILE_SPAN) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_insn, QEMU_PLUGIN_CB_NO_REGS,
                                                   (void *)(uintptr_t)pc);
        }
        if (pc == start_addr) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_start, QEMU_PLUGIN_CB_NO_REGS, NULL);
        } else if (pc == stop_addr) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_stop, QEMU_PLUGIN_CB_NO_REGS, NULL);
        }
    }
}

static void on_exit_cb(qemu_plugin_id_t id, void *userdata)
{
    (void)id;
    (void)userdata;
    if (out) {
        fflush(out);
    }
    if (pcs_out) {
        for (uint64_t i = 0; i < PROFILE_SPAN / 2; i++) {
            if (pc_counts[i]) {
                fprintf(pcs_out, "%llx %llu\n", (unsigned long long)(profile_base + (i << 1)),
                        (unsigned long long)pc_counts[i]);
            }
        }
        fclose(pcs_out);
    }
}

__attribute__((visibility("default"))) int qemu_plugin_install(qemu_plugin_id_t id,
                                                               const struct qemu_info_t *info,
                                                               int argc, char **argv)
{
    (void)info;
    const char *path = NULL;
    const char *pcs_path = NULL;
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        if (strncmp(a, "start=", 6) == 0) {
            start_addr = strtoull(a + 6, NULL, 0);
        } else if (strncmp(a, "stop=", 5) == 0) {
            stop_addr = strtoull(a + 5, NULL, 0);
        } else if (strncmp(a, "out=", 4) == 0) {
            path = a + 4;
        } else if (strncmp(a, "profile=", 8) == 0) {
            profile_region = strtoull(a + 8, NULL, 0);
            profiling = true;
        } else if (strncmp(a, "pcs=", 4) == 0) {
            pcs_path = a + 4;
        } else {
            fprintf(stderr, "stopwatch: unknown argument %s\n", a);
            return -1;
        }
    }
    if (!path || !start_addr || !stop_addr) {
        fprintf(stderr, "stopwatch: needs start=ADDR,stop=ADDR,out=FILE\n");
        return -1;
    }
    out = fopen(path, "w");
    if (!out) {
        perror("stopwatch: out");
        return -1;
    }
    if (profiling) {
        profile_base = start_addr & ~(uint64_t)(PROFILE_SPAN - 1);
        pc_counts = calloc(PROFILE_SPAN / 2, sizeof *pc_counts);
        pcs_out = pcs_path ? fopen(pcs_path, "w") : NULL;
        if (!pc_counts || !pcs_out) {
            fprintf(stderr, "stopwatch: profile=N needs pcs=FILE (writable)\n");
            return -1;
        }
    }
    qemu_plugin_register_vcpu_tb_trans_cb(id, on_translate);
    qemu_plugin_register_atexit_cb(id, on_exit_cb, NULL);
    return 0;
}

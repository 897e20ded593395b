/*  c-pingpong.c -- the floor for bench/scheme-pingpong.scm
 *
 *  The same exchange in C: a parent and a forked echo server over loopback
 *  TCP, a 4-byte payload framed as a netstring ("4:ping,"), written with one
 *  write() per frame and read as the length prefix, then the payload and the
 *  comma.  After a warm-up, times each round trip and prints the MEDIAN, so
 *  that a few trips delayed by the machine's other work do not move it:
 *
 *      bench: c-pingpong-rtt VALUE us
 *
 *  With an argument N it fans out instead, the floor of a request to a lab
 *  of N: N forked echo servers, the frame written to each in turn, then
 *  each echo read; the median time of that round:
 *
 *      bench: c-fanout-NN VALUE us
 */

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#define TRIPS 20000     /* frames echoed; a fan-out to N times TRIPS / N */
#define MAX_SERVERS 256
#define WARM_UP 1000
#define MAX_PAYLOAD 64

static const char payload[] = "ping";

static void die (const char *what) {
  perror(what);
  exit(1);
}

static int write_all (int fd, const char *buf, size_t len) {
  while (len > 0) {
    ssize_t n = write(fd, buf, len);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return -1;
    buf += n;
    len -= (size_t)n;
  }
  return 0;
}

/* Reads exactly len bytes; 0 on success, -1 on error or end of file. */
static int read_all (int fd, char *buf, size_t len) {
  while (len > 0) {
    ssize_t n = read(fd, buf, len);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return -1;
    buf += n;
    len -= (size_t)n;
  }
  return 0;
}

static int write_netstring (int fd, const char *data, size_t len) {
  char frame[MAX_PAYLOAD + 24];
  int head;
  if (len > MAX_PAYLOAD) return -1;
  head = snprintf(frame, sizeof(frame), "%zu:", len);
  memcpy(frame + head, data, len);
  frame[head + len] = ',';
  return write_all(fd, frame, head + len + 1);
}

/* Reads one netstring into buf; its length, or -1 on error, bad framing or
 * end of file.  The length prefix is read a byte at a time so that nothing
 * past the colon is consumed, as the Scheme side does. */
static long read_netstring (int fd, char *buf, size_t max) {
  size_t len = 0;
  int digits = 0;
  char c;
  for (;;) {
    if (read_all(fd, &c, 1) < 0) return -1;
    if (c == ':') break;
    if (c < '0' || c > '9' || ++digits > 9) return -1;
    len = len * 10 + (size_t)(c - '0');
  }
  if (digits == 0 || len > max) return -1;
  if (read_all(fd, buf, len) < 0 || read_all(fd, &c, 1) < 0 || c != ',')
    return -1;
  return (long)len;
}

static void echo (int sock) {
  char buf[MAX_PAYLOAD];
  long n;
  while ((n = read_netstring(sock, buf, sizeof(buf))) >= 0)
    if (write_netstring(sock, buf, (size_t)n) < 0) break;
}

static double now_us (void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec * 1e6 + ts.tv_nsec / 1e3;
}

static void round_trip (const int *socks, int n) {
  char buf[MAX_PAYLOAD];
  int i;
  for (i = 0; i < n; i++)
    if (write_netstring(socks[i], payload, sizeof(payload) - 1) < 0)
      die("write");
  for (i = 0; i < n; i++)
    if (read_netstring(socks[i], buf, sizeof(buf)) != (long)sizeof(payload) - 1
        || memcmp(buf, payload, sizeof(payload) - 1) != 0) {
      fprintf(stderr, "c-pingpong: bad echo\n");
      exit(1);
    }
}

static int compare_doubles (const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double median_round_trip (const int *socks, int n) {
  static double times[TRIPS];
  int i, trips = TRIPS / n;
  for (i = 0; i < WARM_UP / n; i++) round_trip(socks, n);
  for (i = 0; i < trips; i++) {
    double start = now_us();
    round_trip(socks, n);
    times[i] = now_us() - start;
  }
  qsort(times, trips, sizeof(times[0]), compare_doubles);
  return times[trips / 2];
}

/* A listener on a port the kernel picks, so that runs never collide. */
static int listen_loopback (struct sockaddr_in *addr) {
  socklen_t len = sizeof(*addr);
  int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) die("socket");
  memset(addr, 0, sizeof(*addr));
  addr->sin_family = AF_INET;
  addr->sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr->sin_port = 0;
  if (bind(fd, (struct sockaddr *)addr, sizeof(*addr)) < 0) die("bind");
  if (listen(fd, 1) < 0) die("listen");
  if (getsockname(fd, (struct sockaddr *)addr, &len) < 0) die("getsockname");
  return fd;
}

/* A connection to a forked echo server; its pid in *pid.  The server
 * closes its copies of the n connections made before, so that each sees
 * end of file when the parent closes its own. */
static int start_echo_server (const int *before, int n, pid_t *pid) {
  struct sockaddr_in addr;
  int listener = listen_loopback(&addr), sock, i;
  *pid = fork();
  if (*pid < 0) die("fork");
  if (*pid == 0) {
    for (i = 0; i < n; i++) close(before[i]);
    sock = accept(listener, NULL, NULL);
    if (sock < 0) die("accept");
    close(listener);
    echo(sock);
    _exit(0);
  }
  close(listener);
  sock = socket(AF_INET, SOCK_STREAM, 0);
  if (sock < 0 || connect(sock, (struct sockaddr *)&addr, sizeof(addr)) < 0) {
    kill(*pid, SIGKILL);
    die("connect");
  }
  return sock;
}

int main (int argc, char **argv) {
  int n = argc > 1 ? atoi(argv[1]) : 1, i, status;
  int socks[MAX_SERVERS];
  pid_t pids[MAX_SERVERS];
  double median;
  if (n < 1 || n > MAX_SERVERS) {
    fprintf(stderr, "usage: c-pingpong [N], N from 1 to %d\n", MAX_SERVERS);
    return 2;
  }
  for (i = 0; i < n; i++) socks[i] = start_echo_server(socks, i, &pids[i]);
  median = median_round_trip(socks, n);
  for (i = 0; i < n; i++) {
    close(socks[i]);    /* the server sees end of file and exits */
    waitpid(pids[i], &status, 0);
  }
  if (argc > 1) printf("bench: c-fanout-N%d %.1f us\n", n, median);
  else printf("bench: c-pingpong-rtt %.1f us\n", median);
  return 0;
}

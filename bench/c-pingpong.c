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
 *
 *  With "mcast N", the floor of a multicast requester's CPU over a
 *  broadcasting one's: the servers also join a multicast group, and each
 *  writes every datagram sent there back on its connection, as an address
 *  space answers a multicast call.  Rounds of the fan-out take turns with
 *  rounds of one datagram to the group; in both the answers are read as
 *  epoll finds them ready, and the sender, a member of the group as a
 *  requester is, reads its own datagram back.  The sender's CPU per peer
 *  in each, and the ratio:
 *
 *      bench: c-fanout-cpu-per-peer-NN VALUE us
 *      bench: c-mcast-cpu-per-peer-NN VALUE us
 *      bench: c-mcast-over-fanout-cpu-NN VALUE x
 */

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <poll.h>
#include <sys/epoll.h>
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

/* The multicast group of "mcast N", its port the one the kernel gave the
 * sender's socket (group_port), so that runs at once never collide. */
static struct sockaddr_in group;

static int group_socket (void) {
  struct ip_mreq mreq;
  socklen_t len = sizeof(group);
  int fd = socket(AF_INET, SOCK_DGRAM, 0), one = 1;
  if (fd < 0) die("socket");
  mreq.imr_multiaddr = group.sin_addr;
  mreq.imr_interface.s_addr = htonl(INADDR_LOOPBACK);
  if (setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) < 0
      || bind(fd, (struct sockaddr *)&group, sizeof group) < 0
      || setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mreq, sizeof mreq) < 0
      || setsockopt(fd, IPPROTO_IP, IP_MULTICAST_IF, &mreq.imr_interface,
                    sizeof mreq.imr_interface) < 0)
    die("multicast socket");
  if (group.sin_port == 0 && getsockname(fd, (struct sockaddr *)&group, &len) < 0)
    die("getsockname");
  return fd;
}

/* As echo, and each datagram to the group written back on sock.  Sent
 * at once (TCP_NODELAY): the sender, who writes nothing before the next
 * answer, delays its acknowledgement of an echo up to 40 ms, and Nagle's
 * rule would hold the answer that long. */
static void echo_with_group (int sock, int dgram) {
  struct pollfd fds[2] = {{sock, POLLIN, 0}, {dgram, POLLIN, 0}};
  char buf[MAX_PAYLOAD];
  long n;
  int one = 1;
  if (setsockopt(sock, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one) < 0)
    die("TCP_NODELAY");
  for (;;) {
    if (poll(fds, 2, -1) < 0) {
      if (errno == EINTR) continue;
      return;
    }
    if (fds[0].revents) {
      n = read_netstring(sock, buf, sizeof(buf));
      if (n < 0 || write_netstring(sock, buf, (size_t)n) < 0) return;
    }
    if (fds[1].revents) {
      n = recv(dgram, buf, sizeof(buf), 0);
      if (n >= 0 && write_netstring(sock, buf, (size_t)n) < 0) return;
    }
  }
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
static int start_echo_server (const int *before, int n, pid_t *pid, int grouped) {
  struct sockaddr_in addr;
  int listener = listen_loopback(&addr), sock, i;
  *pid = fork();
  if (*pid < 0) die("fork");
  if (*pid == 0) {
    int dgram = grouped ? group_socket() : -1;  /* before the connection */
    for (i = 0; i < n; i++) close(before[i]);
    sock = accept(listener, NULL, NULL);
    if (sock < 0) die("accept");
    close(listener);
    if (grouped) echo_with_group(sock, dgram);
    else echo(sock);
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

static double cpu_us (void) {
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e6 + ts.tv_nsec / 1e3;
}

/* Reads the n answers, "4:ping," on each of socks, as epoll finds them. */
static void read_answers (int ep, const int *socks, int n) {
  static int got[MAX_SERVERS];
  struct epoll_event ready[MAX_SERVERS];
  char buf[MAX_PAYLOAD];
  int left = n, i, k;
  memset(got, 0, sizeof(got[0]) * n);
  while (left > 0) {
    k = epoll_wait(ep, ready, MAX_SERVERS, -1);
    if (k < 0 && errno != EINTR) die("epoll_wait");
    for (i = 0; i < k; i++) {
      int s = ready[i].data.u32;
      ssize_t r = read(socks[s], buf, sizeof(buf));
      if (r < 0 && errno == EAGAIN) continue;
      if (r <= 0) die("read");
      got[s] += (int)r;
      if (got[s] == 7) left--;
    }
  }
}

/* The sender's CPU per peer, the fan-out's and the datagram's, over
 * rounds that take turns after a warm-up. */
static void measure_mcast (const int *socks, int n, int own, double *fanout, double *mcast) {
  struct epoll_event e;
  char buf[MAX_PAYLOAD];
  int ep = epoll_create1(0), i, r, rounds = 4 * TRIPS / n;
  double t0, t1, t2;
  if (ep < 0) die("epoll_create1");
  for (i = 0; i < n; i++) {
    e.events = EPOLLIN;
    e.data.u32 = (unsigned)i;
    if (epoll_ctl(ep, EPOLL_CTL_ADD, socks[i], &e) < 0) die("epoll_ctl");
  }
  *fanout = *mcast = 0;
  for (r = -WARM_UP / n; r < rounds; r++) {
    t0 = cpu_us();
    for (i = 0; i < n; i++)
      if (write_netstring(socks[i], payload, sizeof(payload) - 1) < 0) die("write");
    read_answers(ep, socks, n);
    t1 = cpu_us();
    if (sendto(own, payload, sizeof(payload) - 1, 0, (struct sockaddr *)&group,
               sizeof group) < 0)
      die("sendto");
    read_answers(ep, socks, n);
    if (recv(own, buf, sizeof(buf), 0) < 0) die("recv");
    t2 = cpu_us();
    if (r >= 0) {
      *fanout += t1 - t0;
      *mcast += t2 - t1;
    }
  }
  *fanout /= (double)rounds * n;
  *mcast /= (double)rounds * n;
}

int main (int argc, char **argv) {
  int grouped = argc > 1 && strcmp(argv[1], "mcast") == 0;
  int n = argc > 1 + grouped ? atoi(argv[1 + grouped]) : 1, i, status, own = -1;
  int socks[MAX_SERVERS];
  pid_t pids[MAX_SERVERS];
  double median = 0, fanout = 0, mcast = 0;
  if (n < 1 || n > MAX_SERVERS) {
    fprintf(stderr, "usage: c-pingpong [mcast] [N], N from 1 to %d\n", MAX_SERVERS);
    return 2;
  }
  if (grouped) {
    group.sin_family = AF_INET;
    group.sin_addr.s_addr = inet_addr("239.255.77.10");
    own = group_socket();
  }
  for (i = 0; i < n; i++) socks[i] = start_echo_server(socks, i, &pids[i], grouped);
  if (grouped) {
    for (i = 0; i < n; i++)
      if (fcntl(socks[i], F_SETFL, fcntl(socks[i], F_GETFL) | O_NONBLOCK) < 0)
        die("fcntl");
    measure_mcast(socks, n, own, &fanout, &mcast);
  } else {
    median = median_round_trip(socks, n);
  }
  for (i = 0; i < n; i++) {
    close(socks[i]);    /* the server sees end of file and exits */
    waitpid(pids[i], &status, 0);
  }
  if (grouped) {
    printf("bench: c-fanout-cpu-per-peer-N%d %.1f us\n", n, fanout);
    printf("bench: c-mcast-cpu-per-peer-N%d %.1f us\n", n, mcast);
    printf("bench: c-mcast-over-fanout-cpu-N%d %.2f x\n", n, mcast / fanout);
  } else if (argc > 1) {
    printf("bench: c-fanout-N%d %.1f us\n", n, median);
  } else {
    printf("bench: c-pingpong-rtt %.1f us\n", median);
  }
  return 0;
}

/*  multicast-socket.c -- a UDP socket on an IP multicast group, the C of
 *  (murdoch wire multicast), which multicast.stub binds
 *
 *  Chibi's (chibi net) sends and receives datagrams, and does so without
 *  blocking its other threads, but it cannot join a multicast group: that
 *  takes socket options whose values are C structures.  This module makes
 *  the socket; (chibi net)'s send and receive do the rest.
 */

#include <chibi/eval.h>
#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

static sexp fail (sexp ctx, sexp self, const char *what, const char *irritant) {
  return sexp_user_exception(ctx, self, what, sexp_c_string(ctx, irritant, -1));
}

/* (open-multicast-socket GROUP PORT INTERFACE): a non-blocking UDP socket
 * bound to PORT, member of GROUP on the interface whose address is
 * INTERFACE, sending there with its own datagrams looped back, so that
 * address spaces on one machine hear each other. */
static sexp open_multicast_socket (sexp ctx, sexp self, const char *group,
                                   int port, const char *interface) {
  struct sockaddr_in addr;
  struct ip_mreq mreq;
  struct in_addr ifaddr;
  int fd, one = 1, rcvbuf = 1 << 20;
  unsigned char loop = 1, ttl = 1;
  if (inet_pton(AF_INET, group, &mreq.imr_multiaddr) != 1
      || !IN_MULTICAST(ntohl(mreq.imr_multiaddr.s_addr)))
    return fail(ctx, self, "not an IPv4 multicast group", group);
  if (inet_pton(AF_INET, interface, &ifaddr) != 1)
    return fail(ctx, self, "not an IPv4 interface address", interface);
  mreq.imr_interface = ifaddr;
  fd = socket(AF_INET, SOCK_DGRAM, 0);
  if (fd < 0)
    return fail(ctx, self, strerror(errno), group);
  /* A call to the lab reaches every address space at once, and each
   * answers and beacons: with dozens on one machine the default receive
   * buffer overflows and datagrams are lost.  Best effort: the kernel caps
   * it at net.core.rmem_max. */
  setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
  memset(&addr, 0, sizeof addr);
  addr.sin_family = AF_INET;
  addr.sin_port = htons((unsigned short)port);
  addr.sin_addr = mreq.imr_multiaddr;
  if (setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) < 0
      || bind(fd, (struct sockaddr *)&addr, sizeof addr) < 0
      || setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mreq, sizeof mreq) < 0
      || setsockopt(fd, IPPROTO_IP, IP_MULTICAST_IF, &ifaddr, sizeof ifaddr) < 0
      || setsockopt(fd, IPPROTO_IP, IP_MULTICAST_LOOP, &loop, sizeof loop) < 0
      || setsockopt(fd, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl) < 0
      || fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK) < 0) {
    sexp err = fail(ctx, self, strerror(errno), group);
    close(fd);
    return err;
  }
  return sexp_make_fileno(ctx, sexp_make_fixnum(fd), SEXP_FALSE);
}

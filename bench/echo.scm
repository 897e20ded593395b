;;;; The bare Chibi echo server, the floor of the benches' round trip,
;;;; fan-out and pipelined throughput, and of bench/stages.scm's whole
;;;; message.

;;> Accepts one connection on \var{listener}, which listens on
;;> 127.0.0.1:\var{port}, and writes each netstring of up to
;;> \var{max-frame} bytes back until the peer closes.  With
;;> \var{blocking?}, a read that finds nothing waits in the kernel, as in
;;> C, not in Chibi's scheduler.
(define (echo-connection listener port blocking? max-frame)
  (let* ((addr (get-address-info "127.0.0.1" port))
         (sock (accept listener (address-info-address addr)
                       (address-info-address-length addr)))
         (in (open-input-file-descriptor sock))
         (out (open-output-file-descriptor sock)))
    (if blocking?
        (set-file-descriptor-status!
         sock (bitwise-and (get-file-descriptor-status sock)
                           (bitwise-not open/non-block))))
    (let loop ()
      (let ((frame (read-netstring in max-frame)))
        (unless (eof-object? frame)
          (write-netstring frame out)
          (flush-output-port out)
          (loop))))))

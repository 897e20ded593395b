;;;; Netstrings (D. J. Bernstein): "LENGTH:PAYLOAD,".  The reader is strict,
;;;; as frames come from the network: digits only, no leading zero but for
;;;; the empty payload, at most MAX bytes of payload, and the comma.

;; A peer's bad netstring is a protocol error of the remote-error family.
(define (netstring-fail . parts)
  (apply protocol-fail "netstring" parts))

;;> Whether \var{e} is a bad netstring's error, or another protocol error.
(define netstring-error? remote-protocol-error?)

;;> What was wrong with the netstring.
(define netstring-error-message remote-error-message)

(define (digit-byte? b) (and (>= b 48) (<= b 57)))

;; The length, read a byte at a time to leave the payload in the buffer;
;; a length already over max takes no more digits.
(define (read-netstring-length in max)
  (let loop ((n 0) (digits 0))
    (let ((b (read-u8 in)))
      (cond
       ((eof-object? b)
        (if (zero? digits) b (netstring-fail "truncated length")))
       ((= b 58)                      ; #\:
        (if (zero? digits) (netstring-fail "empty length") n))
       ((not (digit-byte? b))
        (netstring-fail "non-digit byte " (number->string b)
                        " in length"))
       ((and (= digits 1) (zero? n))
        (netstring-fail "leading zero in length"))
       ((> n max)
        (netstring-fail "length over " (number->string max) " bytes"))
       (else (loop (+ (* n 10) (- b 48)) (+ digits 1)))))))

;; The buffer's bytes are copied at once (netstring-scan.c); read-u8 waits
;; to refill an empty one.  The port's end before the last byte is a fault.
(define (read-payload in n)
  (let ((payload (make-bytevector n)))
    (let loop ((have 0))
      (if (= have n)
          payload
          (let ((got (read-buffered-bytes! in payload have n)))
            (if (positive? got)
                (loop (+ have got))
                (let ((b (read-u8 in)))
                  (if (eof-object? b) (netstring-fail "truncated payload"))
                  (bytevector-u8-set! payload have b)
                  (loop (+ have 1)))))))))

;;> Reads one netstring from binary port \var{in}: its payload, or an eof
;;> object at a clean end; a protocol remote-error on anything else.
(define (read-netstring in max)
  (or (take-buffered-netstring in max)  ; netstring-scan.c: a whole frame
      (read-netstring-bytewise in max)))

(define (read-netstring-bytewise in max)
  (let ((n (read-netstring-length in max)))
    (cond
     ((eof-object? n) n)
     ((> n max)
      (netstring-fail "length " (number->string n) " over "
                      (number->string max) " bytes"))
     (else
      (let ((payload (read-payload in n)))
        (let ((comma (read-u8 in)))
          (if (not (eqv? comma 44))
              (netstring-fail "missing comma after payload")))
        payload)))))

;;> Writes \var{payload}, a bytevector or a string (faster: docs/speed.md),
;;> to \var{out} as one netstring, unflushed.
(define (write-netstring payload out)
  (if (string? payload)
      (begin
        (write-string (fixnum->decimal (string-size payload)) out)
        (write-char #\: out)
        (write-string payload out)
        (write-char #\, out))
      (begin
        (write-string (fixnum->decimal (bytevector-length payload)) out)
        (write-u8 58 out)
        (write-bytevector payload out)
        (write-u8 44 out))))

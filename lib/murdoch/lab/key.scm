;;;; The lab's key, part of (murdoch lab).

(define key-bytes 32)

;;> The lab's key as a bytevector, read from its key file.  When the file
;;> does not exist it is made: written under a temporary name with mode
;;> 0600 and linked into place, so that peers starting at once all end up
;;> with the one key that won, and none reads a half-written file.
(define (lab-key lab)
  (let ((file (lab-path lab (lab-setting lab 'key-file))))
    (if (not (file-exists? file))
        (make-key-file file))
    (let ((hex (call-with-input-file file read-line)))
      (if (or (eof-object? hex) (< (string-length hex) 32))
          (error (string-append "the lab's key file is too short " file)))
      (string->utf8 hex))))

(define (make-key-file file)
  (let ((temp (string-append file "." (number->string (current-process-id))
                             ".new")))
    (let ((fd (open temp (bitwise-ior open/write open/create open/exclusive)
                    #o600)))
      (if (not fd) (error (string-append "cannot create the key file " temp)))
      (let ((out (open-output-file-descriptor fd)))
        (write-string (random-hex key-bytes) out)
        (newline out)
        (close-output-port out)))
    (link-file temp file)               ; fails harmlessly if another won
    (delete-file temp)))

(define (random-hex n)
  (let ((bytes (call-with-port (open-binary-input-file "/dev/urandom")
                 (lambda (in) (read-bytevector n in)))))
    (apply string-append
           (map (lambda (b)
                  (string-append (if (< b 16) "0" "") (number->string b 16)))
                (bytevector->list bytes)))))

(define (bytevector->list bv)
  (let loop ((i (- (bytevector-length bv) 1)) (acc '()))
    (if (< i 0) acc (loop (- i 1) (cons (bytevector-u8-ref bv i) acc)))))

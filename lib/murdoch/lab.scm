;;;; The lab file (docs/lab-file.md): who is in the lab and where.
;;
;; Every peer reads the same file, so the lab needs no registry: a uid
;; names an address space, and the file says where it listens.

(define-record-type lab
  (make-lab name directory settings aspaces)
  lab?
  (name lab-name)
  (directory lab-directory)
  (settings lab-settings)
  (aspaces lab-aspaces))

;;> One address space of the lab file.  \var{clauses} keeps the clauses that
;;> later layers read (robot, position, capabilities, load).
(define-record-type lab-aspace
  (make-lab-aspace uid index host port clauses)
  lab-aspace?
  (uid lab-aspace-uid)
  (index lab-aspace-index)
  (host lab-aspace-host)
  (port lab-aspace-port)
  (clauses lab-aspace-clauses))

(define (clause key clauses)
  (find (lambda (c) (and (pair? c) (eq? (car c) key))) clauses))

(define (clause-value key clauses default)
  (cond ((clause key clauses) => cadr) (else default)))

;;> The value of setting \var{key} of the lab, or \var{default}.
(define (lab-setting lab key default)
  (clause-value key (lab-settings lab) default))

;;> The clause \scheme{(key ...)} of an address space, or #f.
(define (lab-aspace-clause a key)
  (clause key (lab-aspace-clauses a)))

(define (lab-port-base settings)
  (cond ((get-environment-variable "MURDOCH_PORT_BASE") => string->number)
        (else (clause-value 'port-base settings 7100))))

;;> A port for a guest, an address space the file does not name (a REPL
;;> that joins the lab): one of port-base + 150 to + 199, by process id.
(define (lab-guest-port lab)
  (+ (lab-port-base (lab-settings lab)) 150 (modulo (current-process-id) 50)))

;;> Reads the lab file at \var{path}.  Errors name the file and the fault.
(define (read-lab path)
  (let ((form (guard (e (#t (error "cannot read the lab file" path
                                   (condition-message e))))
                (call-with-input-file path read))))
    (if (not (and (pair? form) (eq? (car form) 'lab) (pair? (cdr form))
                  (symbol? (cadr form)) (list? (cddr form))))
        (error "a lab file holds one (lab NAME CLAUSE ...) form" path))
    (let* ((clauses (cddr form))
           (settings (remove (lambda (c) (and (pair? c) (eq? (car c) 'aspace)))
                             clauses))
           (base (lab-port-base settings))
           (interface (clause-value 'interface settings "127.0.0.1")))
      (make-lab (cadr form) (path-directory path) settings
                (let loop ((cs clauses) (i 0) (acc '()))
                  (cond
                   ((null? cs) (reverse acc))
                   ((and (pair? (car cs)) (eq? (caar cs) 'aspace))
                    (loop (cdr cs) (+ i 1)
                          (cons (parse-aspace path (car cs) i base interface)
                                acc)))
                   (else (loop (cdr cs) i acc))))))))

(define (condition-message e)
  (if (error-object? e) (error-object-message e) e))

(define (parse-aspace path form index base interface)
  (if (not (and (pair? (cdr form)) (symbol? (cadr form)) (list? (cddr form))))
      (error "an aspace clause is (aspace NAME CLAUSE ...)" path form))
  (let ((clauses (cddr form)))
    (make-lab-aspace (cadr form) index
                     (clause-value 'host clauses interface)
                     (clause-value 'port clauses (+ base index))
                     clauses)))

(define (path-directory path)
  (let loop ((i (- (string-length path) 1)))
    (cond ((< i 0) ".")
          ((char=? (string-ref path i) #\/)
           (if (zero? i) "/" (substring path 0 i)))
          (else (loop (- i 1))))))

;;> A path named in the lab file, which is relative to the file.
(define (lab-path lab file)
  (if (and (> (string-length file) 0) (char=? (string-ref file 0) #\/))
      file
      (string-append (lab-directory lab) "/" file)))

;;> The address space of the lab named \var{uid}, or #f.
(define (lab-aspace-by-uid lab uid)
  (find (lambda (a) (eq? (lab-aspace-uid a) uid)) (lab-aspaces lab)))

;;> The port of the trip server of robot \var{a}: its (robot (trip-port N))
;;> or port-base + 100 + its index.
(define (lab-trip-port lab a)
  (let ((robot (lab-aspace-clause a 'robot)))
    (cond ((and robot (find (lambda (c) (and (pair? c) (eq? (car c) 'trip-port)))
                            (cdr robot)))
           => cadr)
          (else (+ (lab-port-base (lab-settings lab)) 100 (lab-aspace-index a))))))

;;> The uids of the lab's robots, in file order.
(define (lab-robots lab)
  (map lab-aspace-uid
       (filter (lambda (a) (lab-aspace-clause a 'robot)) (lab-aspaces lab))))

;;; The key

(define key-bytes 32)

;;> The lab's key as a bytevector, read from its key file.  When the file
;;> does not exist it is made: written under a temporary name with mode
;;> 0600 and linked into place, so that peers starting at once all end up
;;> with the one key that won, and none reads a half-written file.
(define (lab-key lab)
  (let ((file (lab-path lab (lab-setting lab 'key-file "murdoch.key"))))
    (if (not (file-exists? file))
        (make-key-file file))
    (let ((hex (call-with-input-file file read-line)))
      (if (or (eof-object? hex) (< (string-length hex) 32))
          (error "the lab's key file is too short" file))
      (string->utf8 hex))))

(define (make-key-file file)
  (let ((temp (string-append file "." (number->string (current-process-id))
                             ".new")))
    (let ((fd (open temp (bitwise-ior open/write open/create open/exclusive)
                    #o600)))
      (if (not fd) (error "cannot create the key file" temp))
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
